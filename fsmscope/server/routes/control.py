"""What a page can do to a machine of this process: preempt, hold, set its initial state, start it,
and publish on the in-process bus, through the machine's ``Controls`` (fsm/control/controls.py); the
calls may block (on the machine's locks, or waiting for its publishing process), so they run in a
worker thread, never on the event loop."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Body, Path
from fastapi.concurrency import run_in_threadpool

from fsm.ros.bus import default_bus

from ..control_models import Delivered, InitialStateRequest, PreemptRequest, SeqResponse, StartRequest
from .deps import ERRORS, LEASED, OPERATOR, ClientAddress, HubDep, MachineControls

router = APIRouter(dependencies=OPERATOR, responses=ERRORS, tags=["control"])

TOPIC = Path(min_length=1, max_length=200, pattern=r"^[A-Za-z0-9_.~/-]+$", description="topic name")


@router.post("/api/machines/{name}/preempt", status_code=202, response_model=SeqResponse)
async def preempt(controls: MachineControls, client: ClientAddress,
                  body: Annotated[PreemptRequest | None, Body()] = None) -> SeqResponse:
    reason = body.reason if body is not None else None
    return SeqResponse(seq=await run_in_threadpool(controls.preempt, reason, client))


@router.post("/api/machines/{name}/hold", status_code=202, response_model=SeqResponse,
             description="Let the current run finish, then start no other until the next start "
                         "(a machine its host runs in a loop, such as the demo's episodes; 409 otherwise).")
async def hold(controls: MachineControls, client: ClientAddress,
               body: Annotated[PreemptRequest | None, Body()] = None) -> SeqResponse:
    reason = body.reason if body is not None else None
    return SeqResponse(seq=await run_in_threadpool(controls.hold, reason, client))


@router.post("/api/machines/{name}/initial-state", response_model=SeqResponse, dependencies=LEASED)
async def initial_state(controls: MachineControls, client: ClientAddress,
                        body: InitialStateRequest) -> SeqResponse:
    seq = await run_in_threadpool(controls.set_initial_state, body.path, list(body.states), dict(body.userdata),
                                  client)
    return SeqResponse(seq=seq)


@router.post("/api/machines/{name}/start", status_code=202, response_model=SeqResponse, dependencies=LEASED)
async def start(controls: MachineControls, client: ClientAddress,
                body: Annotated[StartRequest | None, Body()] = None) -> SeqResponse:
    return SeqResponse(seq=await run_in_threadpool(controls.start, client))


@router.post("/api/topics/{topic}", status_code=202, response_model=Delivered)
async def publish_topic(topic: Annotated[str, TOPIC], hub: HubDep, client: ClientAddress,
                        message: Annotated[Any, Body(description="any JSON value: the message")] = None
                        ) -> Delivered:
    def do() -> int:
        delivered = default_bus.publish(topic, message)
        for entry in hub.machines():  # the bus is this process's: its machines record what reached them
            if entry.local is not None and entry.running():
                entry.controls.emit_control("publish", client, "accepted",
                                            params={"topic": topic, "delivered": delivered})
        return delivered

    return Delivered(delivered=await run_in_threadpool(do))
