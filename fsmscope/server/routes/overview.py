"""The fleet overview (fsmscope/server/overview.py): every machine's tile, asked once or streamed.

The stream sends ``{"type": "overview", "now": T, "tiles": [...]}`` at most every ``EVERY`` seconds
and only when a tile changed (``now``: the server's clock, so that a page tells "last seen 3 s ago"
right whatever its own clock says). Its cost does not grow with the events' rate: tiles are read
from the machines' state, which the hub keeps anyway.
"""

from __future__ import annotations

import asyncio
import contextlib
import time

from fastapi import APIRouter, Request, WebSocket

from fsm.observation import schema
from fsm.observation.encoding import dumps

from .. import models
from ..auth import websocket_subprotocol
from .deps import AUTH, READ, READ_ERRORS, refused

router = APIRouter(tags=["machines"])

EVERY = 0.5  # seconds between two looks at the tiles


@router.get("/api/overview", response_model=list[models.Tile], dependencies=AUTH + READ, responses=READ_ERRORS)
async def overview(request: Request) -> list[dict]:
    return request.app.state.overview.tiles()


@router.websocket("/api/overview/stream")
async def overview_stream(websocket: WebSocket) -> None:
    if await refused(websocket):
        return
    await websocket.accept(websocket_subprotocol(websocket))
    tiles = websocket.app.state.overview.tiles
    receiver = asyncio.ensure_future(websocket.receive())  # returns when the client leaves
    last = None
    try:
        while not receiver.done():
            frame = tiles()
            if frame != last:
                await websocket.send_text(dumps(schema.frame.overview(time.time(), frame)).decode())
                last = frame
            await asyncio.wait([receiver], timeout=EVERY)
    finally:
        receiver.cancel()
        with contextlib.suppress(BaseException):
            await receiver
