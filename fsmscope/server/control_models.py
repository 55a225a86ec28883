"""The controls' requests and answers of the REST API (docs/api.md, docs/debugging.md): preempt, hold,
initial state, start, the debugger's, the lease, the bus; OpenAPI is generated from these. What the
API says of machines is fsmscope/server/models.py."""

from __future__ import annotations

from typing import Literal, Optional

from pydantic import BaseModel, ConfigDict, Field

from fsm.observation.schema import DEADMAN_ACTIONS

from .models import BreakpointSpec, JsonValue


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


class StepRequest(BaseModel):
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [{"level": None}, {"level": "/SM_ROOT"}]})

    level: Optional[str] = Field(default=None, max_length=4096, description="a container's path: hold again at "
                                 "its next transition (a step over what runs inside it); null: the next anywhere")


class ForceRequest(BaseModel):
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [
        {"state": "/SM_ROOT/PICK", "outcome": "succeeded"}]})

    state: str = Field(max_length=4096, description="an active (or holding) state's path")
    outcome: str = Field(max_length=1000, description="one of its registered outcomes")


class Breakpoints(BaseModel):
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [{"breakpoints": [
        {"state": "/SM_ROOT/PICK/CLOSE", "at": "before", "when": "attempts > 2"},
        {"state": "/SM_ROOT/PLACE", "at": "after", "outcome": "aborted"}]}]})

    breakpoints: list[BreakpointSpec] = Field(max_length=1000, description="the whole set")


class LeaseHolder(BaseModel):
    page: str = Field(description="the first characters of the holder page's id")
    client: str = Field(description="where it asked from")
    since: float = Field(description="when it took control (seconds since the epoch)")


class Deadman(BaseModel):
    after: float = Field(description="seconds without a heartbeat from the holder before the action")
    action: Literal[DEADMAN_ACTIONS]  # type: ignore[valid-type]


class LeaseState(BaseModel):
    """Who controls a machine (docs/debugging.md, "One operator at a time")."""

    holder: Optional[LeaseHolder] = Field(default=None, description="null: nobody; a page's first control takes it")
    yours: bool = Field(default=False, description="the page that asked (X-Fsmscope-Page) holds it")
    deadman: Deadman
    beat_every: float = Field(description="seconds between the holder page's heartbeats")


class LeaseRequest(BaseModel):
    model_config = ConfigDict(extra="forbid")

    takeover: bool = Field(default=False, description="take it even when another page holds it (recorded)")


class SeqResponse(BaseModel):
    seq: int = Field(description="seq of the control event this request caused")


class Delivered(BaseModel):
    delivered: int = Field(description="subscribers reached")
