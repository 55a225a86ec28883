"""What the routes share: the hub, the machine a path names, the token checks, the documented errors."""

from __future__ import annotations

from typing import Annotated

from fastapi import Depends, HTTPException, Path, Request, WebSocket
from starlette.requests import HTTPConnection

from .. import models
from ..auth import require_operator, require_token, websocket_refusal
from ..local_control import MachineHandle
from ..hub import Hub, MachineEntry
from ..middleware import deny_handshake

ERRORS = {code: {"model": models.Error} for code in (400, 401, 403, 404, 409, 413, 422)}
NAME = Path(min_length=1, max_length=200, description="machine name")
AUTH = [Depends(require_token)]
OPERATOR = [Depends(require_operator)]  # a control: a viewer's token is answered 403


def get_hub(connection: HTTPConnection) -> Hub:
    return connection.app.state.hub


HubDep = Annotated[Hub, Depends(get_hub)]


def get_machine(name: Annotated[str, NAME], hub: HubDep) -> MachineEntry:
    """The machine the path names; 404 when there is none."""
    entry = hub.get(name)
    if entry is None:
        raise HTTPException(404, "no machine named %r" % name)
    return entry


Machine = Annotated[MachineEntry, Depends(get_machine)]


def get_handle(entry: Machine) -> MachineHandle:
    """The control handle of the machine the path names; 409 when it is not in this process."""
    if entry.handle is None:
        if entry.source == "replay":
            raise HTTPException(409, "machine %r is a recording being replayed: nothing to control" % entry.name)
        raise HTTPException(409, "machine %r runs in another process: control it there" % entry.name)
    return entry.handle


Handle = Annotated[MachineHandle, Depends(get_handle)]


def client_address(request: Request) -> str:
    """Who asked, for the ``client`` of the control event a request causes."""
    return request.client.host if request.client else ""


ClientAddress = Annotated[str, Depends(client_address)]


async def deny_websocket(websocket: WebSocket, status: int, detail: str) -> None:
    """Refuse a websocket before its handshake is accepted (see middleware.deny_handshake)."""
    await deny_handshake(websocket.scope, websocket._send, status, detail)


async def refused(websocket: WebSocket, operator: bool = False) -> bool:
    """The Origin and token checks of a websocket, before its handshake; True when it was refused.
    ``operator``: only the operator's token may open it."""
    refusal = websocket_refusal(websocket, operator)
    if refusal is not None:
        await deny_websocket(websocket, *refusal)
    return refusal is not None
