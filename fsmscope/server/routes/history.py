"""A machine's status now or at any past event, its events page by page (fsmscope/server/history.py), and the
statistics of its states counted over them (fsmscope/server/state_stats.py).

Both read what machine threads handed over first (``Fanout.flush``), copy what memory holds on the
loop (``History.view``) and do the rest, file reads included, in the thread pool; what each read
costs is measured and charged to its client's budget (fsmscope/server/read_budget.py). The summary, asked
every second by a page, is kept until the machine has a new event (fsmscope/server/read_cache.py).
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Callable, Literal, Optional

from fastapi import APIRouter, HTTPException, Query, Request
from fastapi.responses import Response

from fsm.observation.encoding import dumps
from fsm.observation import structure
from fsm.observation.schema import KINDS, MAX_PATH

from .. import models
from ..history import DEFAULT_LIMIT, MAX_LIMIT, HistoryView
from ..read_budget import Meter
from ..read_cache import cached
from .deps import AUTH, READ_ERRORS, HubDep, Machine, ReadMeter

router = APIRouter(dependencies=AUTH, tags=["machines"])

PAST_ERRORS = {**READ_ERRORS,
               410: {"model": models.Error, "description": "older than the history kept (the message says how far "
                     "back it reaches)"},
               416: {"model": models.Error, "description": "beyond the machine's last event"}}
SEQ_EXAMPLES = {"an event": {"value": 1200, "description": "the status right after event 1200"}}
T_EXAMPLES = {"an instant": {"value": 1700000000.5, "description": "the status after the last event at or "
                             "before this time"}}


async def answer(hub: HubDep, entry: Machine, meter: Meter, question: Callable[[HistoryView], Any]) -> Any:
    """``question(view)`` on a view of the machine's history, in the thread pool, measured (what it refuses
    is answered as any ``Refused`` is, by the app)."""
    hub.fanout.flush()
    view = meter.run(entry.past.view)
    return await meter.in_thread(question, view)


@router.get("/api/machines/{name}/status", response_model=models.MachineStatus, responses=PAST_ERRORS)
async def status(hub: HubDep, entry: Machine, meter: ReadMeter,
                 seq: Annotated[Optional[int], Query(ge=0, description="the status right after this event",
                                                     openapi_examples=SEQ_EXAMPLES)] = None,
                 t: Annotated[Optional[float], Query(description="the status after the last event at or before "
                                                     "this time (seconds)", openapi_examples=T_EXAMPLES)] = None,
                 ) -> Response:
    """The machine's status now, or after event ``seq``, or at time ``t`` (one of them at most)."""
    if seq is not None and t is not None:
        raise HTTPException(422, "give seq or t, not both")
    if t is not None and not math.isfinite(t):
        raise HTTPException(422, "t must be a finite number of seconds, not %s" % t)
    if seq is None and t is None:
        data = meter.run(entry.feed.status_dict)
    else:
        data = await answer(hub, entry, meter, lambda view: view.status_at(seq, t))
    return Response(meter.run(dumps, data), media_type="application/json")


@router.get("/api/machines/{name}/history", response_model=models.HistoryPage, responses=PAST_ERRORS)
async def history(hub: HubDep, entry: Machine, meter: ReadMeter,
                  since: Annotated[Optional[int], Query(ge=0, description="from this seq (default: the oldest "
                                                        "kept)")] = None,
                  until: Annotated[Optional[int], Query(ge=0, description="to this seq (default: the last)")] = None,
                  limit: Annotated[int, Query(ge=1, le=MAX_LIMIT, description="events at most")] = DEFAULT_LIMIT,
                  kinds: Annotated[Optional[str], Query(max_length=1000, description="only these kinds, "
                                                        "comma-separated", examples=["transition,error"])] = None,
                  path: Annotated[Optional[str], Query(max_length=2000, description="only events of this path "
                                                       "(exact)")] = None,
                  order: Annotated[Literal["asc", "desc"], Query(description="desc: the newest `limit` of the "
                                                                 "range (still oldest first), to page backwards")
                                   ] = "asc",
                  ) -> Response:
    """Events with since <= seq <= until, oldest first, a page at a time."""
    wanted = None
    if kinds is not None:
        wanted = {kind.strip() for kind in kinds.split(",") if kind.strip()}
        unknown = sorted(wanted - set(KINDS))
        if unknown:
            raise HTTPException(422, "kinds: %r is not an event kind (%s)" % (unknown[0][:50], ", ".join(KINDS)))
    page = await answer(hub, entry, meter, lambda view: view.page(since, until, limit, wanted, path, order))
    return Response(meter.run(page.to_json), media_type="application/json")


@router.get("/api/machines/{name}/summary", response_model=models.StateSummary, responses=PAST_ERRORS)
async def summary(request: Request, hub: HubDep, entry: Machine, meter: ReadMeter,
                  path: Annotated[Optional[str], Query(max_length=MAX_PATH, description="only this state or "
                                                       "container (default: every state visited)")] = None,
                  ) -> Response:
    """Per-state statistics (visits, time in state, last outcome), as ``fsmscope replay`` counts them; the
    same answer (and ETag) until the machine has a new event."""
    root = entry.feed.status.structure
    if path is not None and structure.node_at(root, path) is None:
        raise HTTPException(404, "machine %r has no state %r" % (entry.name, path[:200]))
    hub.fanout.flush()
    view = meter.run(entry.past.view)
    span = meter.run(view.span)
    key = ("summary", path, span["first_seq"], span["last_seq"])
    answers = entry.answers  # the epoch's (a restart meanwhile starts a new one)
    found = answers.get(key)
    if found is None:
        data = await meter.in_thread(entry.stats.answer, view, root, path)
        found = meter.run(lambda: cached(dumps(data)))
        if data["complete"]:  # else the next question counts on
            answers.put(key, found)
    return found.response(request)
