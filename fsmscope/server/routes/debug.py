"""The debugger's controls (docs/debugging.md): pause, resume, step, force an outcome, and the
breakpoints as a set to read and replace, through the machine's ``Controls`` (a local machine's
debugger is fsm/control/debug.py); the calls may block briefly on the debugger's lock (or wait for
a publishing process), so they run in a worker thread."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body
from fastapi.concurrency import run_in_threadpool

from ..control_models import Breakpoints, ForceRequest, SeqResponse, StepRequest
from ..models import BreakpointSpec
from .deps import AUTH, ERRORS, LEASED, OPERATOR, READ, READ_ERRORS, ClientAddress, MachineControls

router = APIRouter(dependencies=AUTH, responses=ERRORS, tags=["debug"])


@router.post("/api/machines/{name}/pause", status_code=202, response_model=SeqResponse,
             dependencies=OPERATOR + LEASED,
             description="Hold at the next transition boundary anywhere: the running state runs on until it returns.")
async def pause(controls: MachineControls, client: ClientAddress) -> SeqResponse:
    return SeqResponse(seq=await run_in_threadpool(controls.pause, client))


@router.post("/api/machines/{name}/resume", status_code=202, response_model=SeqResponse,
             dependencies=OPERATOR + LEASED)
async def resume(controls: MachineControls, client: ClientAddress) -> SeqResponse:
    return SeqResponse(seq=await run_in_threadpool(controls.resume, client))


@router.post("/api/machines/{name}/step", status_code=202, response_model=SeqResponse,
             dependencies=OPERATOR + LEASED,
             description="Let one transition happen, then hold again (409 when the machine is not paused).")
async def step(controls: MachineControls, client: ClientAddress,
               body: Annotated[StepRequest | None, Body()] = None) -> SeqResponse:
    level = body.level if body is not None else None
    return SeqResponse(seq=await run_in_threadpool(controls.step, level, client))


@router.post("/api/machines/{name}/force", status_code=202, response_model=SeqResponse,
             dependencies=OPERATOR + LEASED,
             description="The state ends with this outcome: asked to preempt if it runs, taken at once if it holds "
                         "(422 for an unknown state or outcome, 409 when the state is not active).")
async def force(controls: MachineControls, client: ClientAddress, body: ForceRequest) -> SeqResponse:
    return SeqResponse(seq=await run_in_threadpool(controls.force, body.state, body.outcome, client))


@router.get("/api/machines/{name}/breakpoints", response_model=Breakpoints, dependencies=READ, responses=READ_ERRORS)
async def breakpoints(controls: MachineControls) -> Breakpoints:
    listed = await run_in_threadpool(controls.breakpoints)  # a remote machine's wait for its publisher's answer
    return Breakpoints(breakpoints=[BreakpointSpec(**bp) for bp in listed])


@router.put("/api/machines/{name}/breakpoints", response_model=Breakpoints, dependencies=OPERATOR + LEASED,
            description="Replace the whole set, all or none (422 saying which breakpoint is wrong and, for a "
                        "condition, at which column).")
async def set_breakpoints(controls: MachineControls, client: ClientAddress,
                          body: Breakpoints) -> Breakpoints:
    specs = [bp.model_dump() for bp in body.breakpoints]
    listed = await run_in_threadpool(controls.set_breakpoints, specs, client)
    return Breakpoints(breakpoints=[BreakpointSpec(**bp) for bp in listed])
