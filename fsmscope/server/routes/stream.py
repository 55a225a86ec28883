"""The live stream of one machine's events (docs/api.md, "Stream"), and the send path it writes through.

A transition reaches the browser in three hops: the machine's ``fanout.Observer`` (machine
thread), ``Feed.take_handoff`` (event loop), and this route's sender, ``Fanout.run_client``,
which writes each frame with the server's own ``send`` (at the pace the client asks for, if any). ``KeepServerSend`` (installed by the
app outside Starlette's wrappers) keeps that ``send`` in the scope: frames skip the per-message
wrappers, and a stalled socket can be aborted through the protocol the ``send`` is bound to.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
from typing import Any, Callable

from fastapi import APIRouter, WebSocket

from ..auth import websocket_subprotocol
from ..fanout import MAX_PACE, Client
from .deps import HubDep, deny_websocket, refused

router = APIRouter()

SERVER_SEND = "fsmscope.server_send"  # the scope key KeepServerSend fills


class KeepServerSend:
    """Pure ASGI: keeps each websocket's ``send``, as the server gave it, in its scope."""

    def __init__(self, app: Any) -> None:
        self.app = app

    async def __call__(self, scope: dict, receive: Any, send: Any) -> None:
        if scope["type"] == "websocket":
            scope[SERVER_SEND] = send
        await self.app(scope, receive, send)


def _abort(server_send: Any) -> Callable[[], None] | None:
    """A way to drop a stalled socket without a clean close (which would wait for unsent data)."""
    protocol = getattr(server_send, "__self__", None)
    transport = getattr(protocol, "transport", None)
    if transport is None or not hasattr(transport, "abort"):
        return None
    return transport.abort


@router.websocket("/api/machines/{name}/stream")
async def stream(websocket: WebSocket, name: str, hub: HubDep) -> None:
    if await refused(websocket):
        return
    since_text = websocket.query_params.get("since")
    since = None
    if since_text is not None:
        try:
            since = int(since_text)
        except ValueError:
            await deny_websocket(websocket, 422, "since must be an integer")
            return
    entry = hub.get(name)
    if entry is None:
        await deny_websocket(websocket, 404, "no machine named %r" % name)
        return
    await websocket.accept(websocket_subprotocol(websocket))
    server_send = websocket.scope[SERVER_SEND]

    async def send(frame: str) -> None:
        await server_send({"type": "websocket.send", "text": frame})

    fanout = hub.fanout
    client = fanout.subscribe(entry.feed, since, _abort(server_send))
    sender = asyncio.ensure_future(fanout.run_client(client, send))
    client.task = sender
    receiver = asyncio.ensure_future(_receive(websocket, client))
    try:
        await asyncio.wait([sender, receiver], return_when=asyncio.FIRST_COMPLETED)
    finally:
        for task in (sender, receiver):
            task.cancel()
        fanout.unsubscribe(client)
        for task in (sender, receiver):
            with contextlib.suppress(BaseException):
                await task


async def _receive(websocket: WebSocket, client: Client) -> None:
    """The client's messages: ``{"type": "pace", "ms": N}``; anything else closes the stream with code
    1007 and says why. Returns when the client leaves."""
    while True:
        message = await websocket.receive()
        if message["type"] == "websocket.disconnect":
            return
        try:
            client.repace(pace_of(message.get("text")))
        except ValueError as exc:
            await websocket.close(1007, str(exc)[:120])
            return


def pace_of(text: str | None) -> float:
    """The seconds a pace message asks for; ValueError saying what is wrong with any other message."""
    try:
        message = json.loads(text) if text is not None else None
    except ValueError:
        raise ValueError("a message must be JSON text") from None
    if not isinstance(message, dict) or message.get("type") != "pace":
        raise ValueError('the only message is {"type": "pace", "ms": N}')
    ms = message.get("ms")
    if isinstance(ms, bool) or not isinstance(ms, int) or not 0 <= ms <= MAX_PACE * 1000:
        raise ValueError("pace ms must be an integer from 0 to %d" % (MAX_PACE * 1000))
    return ms / 1000
