"""What the routes share: the hub, the machine a path names, the token checks, the documented errors."""

from __future__ import annotations

import asyncio
import re
from typing import Annotated, AsyncIterator

from fastapi import Depends, HTTPException, Path, Request, WebSocket
from starlette.requests import HTTPConnection

from fsm.control.controls import Controls, Refused

from .. import models
from ..auth import OPERATOR as OPERATOR_ROLE, VIEWER_REFUSAL, require_token, websocket_refusal
from ..hub import Hub, MachineEntry
from ..lease import LeaseHeld
from ..lease_control import LeaseControl
from ..middleware import deny_handshake
from ..read_budget import REQUEST_COST, Meter, ReadBudget, retry_after

ERRORS = {code: {"model": models.Error} for code in (400, 401, 403, 404, 409, 413, 422)}
NAME = Path(min_length=1, max_length=200, description="machine name")
AUTH = [Depends(require_token)]
CONTROL_PATH = re.compile(r"^/api/machines/\{name\}/([a-z-]+)")  # a control's route: its action


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


def get_controls(entry: Machine) -> Controls:
    """The controls of the machine the path names (fsm/control/controls.py), whatever kind of machine it
    is; 409 saying why when nothing takes them now."""
    controls = entry.controls
    unavailable = controls.capabilities().unavailable
    if unavailable is not None:
        raise Refused(409, unavailable)
    return controls


MachineControls = Annotated[Controls, Depends(get_controls)]


PAGE_HEADER = "x-fsmscope-page"  # the page a request comes from (fsmscope/static/api.js PAGE_ID): who holds a lease
PAGE_ID = re.compile(r"^[A-Za-z0-9_-]{1,64}$")


def page_of(request: Request) -> str | None:
    """The page a request comes from; None for a script that sends none."""
    page = request.headers.get(PAGE_HEADER)
    if page is None:
        return None
    if not PAGE_ID.match(page):
        raise HTTPException(422, "the X-Fsmscope-Page header must be 1 to 64 letters, digits, '-' or '_'")
    return page


Page = Annotated[str | None, Depends(page_of)]


def client_address(request: Request, role: Annotated[str, Depends(require_token)], page: Page) -> str:
    """Who asked, for the ``client`` of the control event a request causes: the address, the role,
    and the page (the lease's holder, when it is one), e.g. "127.0.0.1 (operator, page 3f2a9c1d)"."""
    address = request.client.host if request.client else ""
    return "%s (%s%s)" % (address, role, ", page %s" % page[:8] if page else "")


ClientAddress = Annotated[str, Depends(client_address)]


def record_refusal(request: Request, client: str, why: str) -> None:
    """A control refused before it reached the machine the path names, written in that machine's audit
    all the same (fsmscope/server/refusals.py); nothing when there is no such machine."""
    found = CONTROL_PATH.match(getattr(request.scope.get("route"), "path", ""))
    entry = request.app.state.hub.get(request.path_params.get("name", ""))
    if found is not None and entry is not None:
        address = request.client.host if request.client else ""
        request.app.state.refusals.record(entry.controls, entry.name, address, found.group(1), client, why)


def require_operator(request: Request, role: Annotated[str, Depends(require_token)], page: Page) -> None:
    """Dependency for every control: 403 for a viewer's token, which the machine's audit records."""
    if role != OPERATOR_ROLE:
        record_refusal(request, client_address(request, role, page), VIEWER_REFUSAL)
        raise HTTPException(403, VIEWER_REFUSAL)


OPERATOR = [Depends(require_operator)]  # a control: a viewer's token is answered 403


async def read_budget(request: Request, role: Annotated[str, Depends(require_token)],
                      page: Page) -> AsyncIterator[Meter]:
    """Dependency of every read: its client's budget of the server's time (fsmscope/server/read_budget.py). A read
    over it waits for it, or is answered 429 with Retry-After; the read's cost is charged when it is done."""
    budget: ReadBudget = request.app.state.reads
    keys = budget.keys(request.client.host if request.client else "", role, page)
    wait = budget.wait(keys)
    if wait > budget.hold:
        await asyncio.sleep(budget.hold)
        budget.charge(keys, REQUEST_COST)
        retry = retry_after(budget.wait(keys))
        raise HTTPException(429, budget.refusal(retry), headers={"Retry-After": str(retry)})
    if wait > 0:
        await asyncio.sleep(wait)
    meter = Meter()
    try:
        yield meter
    finally:
        budget.charge(keys, REQUEST_COST + meter.seconds)


ReadMeter = Annotated[Meter, Depends(read_budget)]
READ = [Depends(read_budget)]
READ_ERRORS = {**ERRORS, 429: {"model": models.Error, "description": "this client's budget of the server's time "
                                "for reads is spent: retry after the seconds Retry-After says"}}


def get_leases(connection: HTTPConnection) -> LeaseControl:
    return connection.app.state.leases


Leases = Annotated[LeaseControl, Depends(get_leases)]


def require_lease(request: Request, entry: Machine, controls: MachineControls, page: Page, client: ClientAddress,
                  leases: Leases) -> None:
    """Dependency of a control that needs the operator lease (fsmscope/server/lease.py): 409 saying who holds it
    when another page does, which the machine's audit records; a page's first control takes a free one."""
    try:
        leases.admit(entry, page, client)
    except LeaseHeld as err:
        record_refusal(request, client, str(err))
        raise HTTPException(409, str(err)) from None


LEASED = [Depends(require_lease)]


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
