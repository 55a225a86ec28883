"""The door for other processes' machines: ``server.publisher.Publisher`` sends their events here
(docs/api.md, "Ingest"); each is checked against the schema before it reaches the hub."""

from __future__ import annotations

from typing import Any

import orjson
from fastapi import APIRouter, WebSocket
from starlette.websockets import WebSocketDisconnect

from ..auth import websocket_subprotocol
from .deps import HubDep, refused

router = APIRouter()

NOT_EVENTS = "frames must be JSON arrays of events"


@router.websocket("/api/ingest")
async def ingest(websocket: WebSocket, hub: HubDep) -> None:
    if await refused(websocket, operator=True):
        return
    await websocket.accept(websocket_subprotocol(websocket))
    fed: set[str] = set()  # the machines this publisher feeds: shown disconnected when it leaves
    try:
        while True:
            message = await websocket.receive()
            if message["type"] == "websocket.disconnect":
                return
            data = message.get("text")
            if data is None:
                data = message.get("bytes") or b""
            try:
                events = orjson.loads(data)
            except orjson.JSONDecodeError:
                await websocket.close(1007, NOT_EVENTS)
                return
            if isinstance(events, dict):
                events = [events]
            if not isinstance(events, list):
                await websocket.close(1007, NOT_EVENTS)
                return
            for event in events:
                problem = hub.ingest(event)
                if problem is None:
                    fed.add(event["machine"])
                    hub.get(event["machine"]).connected = True
                    continue
                await websocket.send_text(orjson.dumps(
                    {"type": "rejected", "reason": problem, "machine": _field(event, "machine"),
                     "seq": _field(event, "seq")}).decode())
    except WebSocketDisconnect:
        return
    finally:
        for name in fed:
            entry = hub.get(name)
            if entry is not None and entry.source == "ingest":
                entry.connected = False


def _field(event: Any, name: str) -> Any:
    """A refused event's field, echoed back to its publisher only when it is a plain scalar."""
    value = event.get(name) if isinstance(event, dict) else None
    return value if type(value) in (str, int) else None
