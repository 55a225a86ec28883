"""Request and response models of the REST API (docs/api.md); OpenAPI is generated from these."""

from __future__ import annotations

from typing import Any, Literal, Optional

from pydantic import BaseModel, ConfigDict, Field

from fsm.observation.schema import SOURCES

JsonValue = Any


class Error(BaseModel):
    detail: str = Field(description="human readable message")


class Health(BaseModel):
    ok: bool = True


class Scene(BaseModel):
    """Where the 3D view of the simulated robot is served (None: this server has none)."""
    url: str | None = None


class MachineInfo(BaseModel):
    name: str
    running: bool
    outcome: Optional[str] = None
    last_seq: int
    root_path: Optional[str] = None
    can_start: bool
    can_hold: bool = Field(default=False, description="its host runs it in a loop that POST .../hold can stop "
                           "after the current run")
    held: bool = Field(default=False, description="a hold was asked and no start has come since")
    source: Literal[SOURCES]  # type: ignore[valid-type]
    connected: Optional[bool] = Field(default=None, description="a machine of another process: whether its "
                                      "publisher is connected (null for the others)")
    rejected: int = Field(default=0, description="events refused at the door for not fitting the schema")


class Transition(BaseModel):
    model_config = ConfigDict(populate_by_name=True)

    from_: str = Field(alias="from")
    outcome: str
    to: Optional[str] = None


class StructureNode(BaseModel):
    """A node of a ``structure`` event (docs/events.md); containers carry children and transitions."""

    model_config = ConfigDict(extra="allow")

    label: str
    path: str
    type: str
    container: bool
    outcomes: list[str]
    input_keys: list[str]
    output_keys: list[str]
    remapping: dict[str, str]
    initial: Optional[list[str]] = None
    children: Optional[list[StructureNode]] = None
    transitions: Optional[list[Transition]] = None


class ContainerStatus(BaseModel):
    active: list[str]
    initial: list[str]
    userdata: dict[str, JsonValue]
    running: bool
    outcome: Optional[str] = None


class PendingPreempt(BaseModel):
    seq: int
    t: float = Field(description="when it was requested (wall clock, seconds)")
    path: str = Field(description="the container it was requested of")
    serviced: list[str] = Field(description="the states that serviced it so far")


class MachineStatus(BaseModel):
    """``fsm.observation.status.Status.to_dict()`` without ``structure``."""

    machine: str
    run: Optional[str] = None
    root_path: Optional[str] = None
    containers: dict[str, ContainerStatus]
    running: bool
    outcome: Optional[str] = None
    error: Optional[dict[str, JsonValue]] = None
    last_seq: int
    last_t: Optional[float] = None
    run_seq: int = Field(default=0, description="the seq of the current run's first event")
    preempt: Optional[PendingPreempt] = Field(default=None, description="a preempt requested and not over yet")
    preempt_waiting_on: list[str] = Field(default_factory=list, description="the active states that have not "
                                          "serviced the pending preempt")


class PreemptRequest(BaseModel):
    model_config = ConfigDict(extra="forbid")

    reason: Optional[str] = Field(default=None, max_length=1000)


class InitialStateRequest(BaseModel):
    model_config = ConfigDict(extra="forbid")

    path: Optional[str] = Field(default=None, max_length=2000, description="container path; default: the root")
    states: list[str] = Field(default_factory=list, max_length=100)
    userdata: dict[str, JsonValue] = Field(default_factory=dict)


class StartRequest(BaseModel):
    model_config = ConfigDict(extra="forbid")


class SeqResponse(BaseModel):
    seq: int = Field(description="seq of the control event this request caused")


class Delivered(BaseModel):
    delivered: int = Field(description="subscribers reached")


StructureNode.model_rebuild()
