"""The operator lease of a machine (docs/debugging.md, "One operator at a time"): who controls it,
taking and taking over control, the holder's heartbeat, giving it up. The leases are
fsmscope/server/lease.py; their events and the deadman fsmscope/server/lease_control.py."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, HTTPException, Request
from fastapi.concurrency import run_in_threadpool

from ..control_models import Deadman, LeaseHolder, LeaseRequest, LeaseState
from ..lease import BEAT_EVERY, Lease, LeaseHeld, short
from .deps import AUTH, ERRORS, OPERATOR, ClientAddress, Leases, Machine, MachineControls, Page, record_refusal

router = APIRouter(dependencies=AUTH, responses=ERRORS, tags=["lease"])


def _state(leases: Leases, name: str, page: str | None) -> LeaseState:
    lease = leases.leases.holder(name)
    deadman = leases.leases.deadman
    return LeaseState(
        holder=_holder(lease), yours=lease is not None and lease.page == page,
        deadman=Deadman(after=deadman.after, action=deadman.action), beat_every=BEAT_EVERY)


def _holder(lease: Lease | None) -> LeaseHolder | None:
    return None if lease is None else LeaseHolder(page=short(lease.page), client=lease.client,
                                                         since=lease.since)


def _needs_page(page: str | None) -> str:
    if page is None:
        raise HTTPException(422, "a lease is held by a page: send its id in the X-Fsmscope-Page header")
    return page


@router.get("/api/machines/{name}/lease", response_model=LeaseState)
async def lease(entry: Machine, leases: Leases, page: Page) -> LeaseState:
    return _state(leases, entry.name, page)


@router.post("/api/machines/{name}/lease", response_model=LeaseState, dependencies=OPERATOR,
             description="Take control of the machine (409 saying who holds it, unless `takeover`: then "
                         "the other page loses it, and the event says so).")
async def take(request: Request, entry: Machine, controls: MachineControls, leases: Leases, page: Page,
               client: ClientAddress, body: Annotated[LeaseRequest | None, Body()] = None) -> LeaseState:
    page = _needs_page(page)
    takeover = body.takeover if body is not None else False
    try:
        await run_in_threadpool(leases.take, entry, page, client, takeover)
    except LeaseHeld as err:
        await run_in_threadpool(record_refusal, request, client, str(err))
        raise HTTPException(409, str(err)) from None
    return _state(leases, entry.name, page)


@router.post("/api/machines/{name}/lease/beat", response_model=LeaseState, dependencies=OPERATOR,
             description="The holder page's heartbeat (409 when it no longer holds the lease: it lapsed, or "
                         "another page took it over).")
async def beat(entry: Machine, leases: Leases, page: Page) -> LeaseState:
    page = _needs_page(page)
    try:
        leases.beat(entry, page)
    except LeaseHeld as err:
        raise HTTPException(409, str(err)) from None
    return _state(leases, entry.name, page)


@router.delete("/api/machines/{name}/lease", response_model=LeaseState, dependencies=OPERATOR,
               description="Give control up (nothing happens to the machine).")
async def release(entry: Machine, controls: MachineControls, leases: Leases, page: Page, client: ClientAddress
                  ) -> LeaseState:
    page = _needs_page(page)
    if not await run_in_threadpool(leases.release, entry, page, client):
        raise HTTPException(409, "this page does not control machine %r" % entry.name)
    return _state(leases, entry.name, page)
