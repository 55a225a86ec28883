"""A machine's timeline (fsmscope/server/timeline.py): its span, bands, ticks and transition seqs, at a zoom.

A page asks it again every second while a live run grows: the answer is kept until the machine has a
new event (fsmscope/server/read_cache.py), and what it costs is charged to the client's budget (fsmscope/server/read_budget.py).
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Optional

from fastapi import APIRouter, HTTPException, Query, Request
from fastapi.responses import Response

from fsm.observation.encoding import dumps

from .. import models
from ..read_cache import cached
from .deps import AUTH, READ_ERRORS, HubDep, Machine, ReadMeter

router = APIRouter(dependencies=AUTH, tags=["machines"])

MAX_BUCKETS = 10_000


@router.get("/api/machines/{name}/timeline", response_model=models.Timeline, responses=READ_ERRORS)
async def timeline(request: Request, entry: Machine, hub: HubDep, meter: ReadMeter,
                   since_t: Annotated[Optional[float], Query(description="from this time (default: the first "
                                                             "event's)")] = None,
                   until_t: Annotated[Optional[float], Query(description="to this time (default: the last "
                                                             "event's)")] = None,
                   buckets: Annotated[int, Query(ge=1, le=MAX_BUCKETS, description="bands per container, about; "
                                                 "states shorter than a bucket are drawn as one '…' band")] = 1000,
                   ) -> Response:
    for field, value in (("since_t", since_t), ("until_t", until_t)):
        if value is not None and not math.isfinite(value):
            raise HTTPException(422, "%s must be a finite number of seconds, not %s" % (field, value))
    if since_t is not None and until_t is not None and since_t > until_t:
        raise HTTPException(422, "since_t (%r) is after until_t (%r)" % (since_t, until_t))
    hub.fanout.flush()
    index = entry.timeline
    view = meter.run(entry.past.view)
    last = index.last
    key = ("timeline", since_t, until_t, buckets, last and last["seq"], meter.run(view.span)["first_seq"])
    answers = entry.answers  # the epoch's (a restart meanwhile starts a new one)
    found = answers.get(key)
    if found is None:
        answer = await meter.in_thread(_answer, index, view, since_t, until_t, buckets)
        found = meter.run(lambda: cached(dumps(answer)))
        answers.put(key, found)
    return found.response(request)


def _answer(index: Any, history: Any, since_t: float | None, until_t: float | None, buckets: int) -> dict:
    """The timeline index's answer, and how far back the machine's history can show an instant (in a thread:
    ``history`` is a view taken on the loop)."""
    answer = index.answer(since_t, until_t, buckets)
    answer["history_from"] = history.span()["first_seq"]
    return answer
