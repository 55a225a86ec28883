"""The door for other processes' machines: ``server.publisher.Publisher`` sends their events here
(docs/api.md, "Ingest"); each is checked against the schema before it reaches the hub. The same
connection carries the controls of the machines its publisher said take them (fsmscope/server/remote_control.py)."""

from __future__ import annotations

import asyncio
from typing import Any

import orjson
from fastapi import APIRouter, WebSocket
from starlette.websockets import WebSocketDisconnect

from fsm.observation import schema

from ..auth import websocket_subprotocol
from ..remote_control import IngestLink
from .deps import HubDep, refused

router = APIRouter()

NOT_EVENTS = "frames must be JSON arrays of events"


@router.websocket("/api/ingest")
async def ingest(websocket: WebSocket, hub: HubDep) -> None:
    if await refused(websocket, operator=True):
        return
    await websocket.accept(websocket_subprotocol(websocket))
    link = IngestLink(hub, websocket.send_text, asyncio.get_running_loop())
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
            if isinstance(events, dict) and "type" in events:  # not an event: a hello or an answer
                problem = _said(link, events)
                if problem is not None:
                    await websocket.close(1007, problem)
                    return
                continue
            if isinstance(events, dict):
                events = [events]
            if not isinstance(events, list):
                await websocket.close(1007, NOT_EVENTS)
                return
            for event in events:
                problem = hub.ingest(event)
                if problem is None:
                    link.feeds(hub.get(event["machine"]))
                    continue
                await link.send(schema.frame.rejected(problem, _field(event, "machine"), _field(event, "seq")))
    except WebSocketDisconnect:
        return
    finally:
        link.close()


def _said(link: IngestLink, frame: dict) -> str | None:
    """A publisher's frame other than events; returns why it closes the connection (None: taken)."""
    kind = frame["type"]
    if kind == "hello":
        return link.hello(frame)
    if kind == "answer":
        return link.answer(frame)
    return "unknown frame type %s" % ascii(kind)[:40]  # a close reason holds at most 123 bytes


def _field(event: Any, name: str) -> Any:
    """A refused event's field, echoed back to its publisher only when it is a plain scalar."""
    value = event.get(name) if isinstance(event, dict) else None
    return value if type(value) in (str, int) else None
