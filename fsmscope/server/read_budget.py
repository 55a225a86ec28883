"""Each client's budget of the server's time for reads (docs/api.md, "Read budget").

The server answers reads in the process that runs the machine: every millisecond of Python it spends
on a read is a millisecond the machine's thread waits for the GIL (one client asking GET .../summary
back to back cut a two-state loop to 14 % of its events/s: bench/reads_cost.py). So what a client's
reads may cost is bounded, in the server's own time: a token bucket per client, in seconds of work,
filled at ``RATE`` (a share of one core) up to ``BURST``. A read is charged what it took (the CPU
time of its thread's work, measured, and ``REQUEST_COST`` for uvicorn's and FastAPI's part): a cheap
read costs little and a costly one much, whatever made it costly (a long run, a question about the
recording on disk, a big machine). A read that finds its client in debt waits for the bucket to refill
when that takes at most ``HOLD`` seconds (a page dragging the playhead is slowed, not refused); a
longer debt is answered 429 with Retry-After, after ``HOLD`` seconds, so that a client asking again
at once, without waiting, still asks at most once per ``HOLD`` and costs the server next to nothing.

A client is a page (its X-Fsmscope-Page header) or a script (none), at an address, with a role. All
of an address's clients of one role share a bucket ``SHARE`` times as big besides their own: a
script that makes up a new page for every request is still bounded, and a viewer never spends the
operator's budget.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Callable, Hashable, TypeVar

from fastapi.concurrency import run_in_threadpool

RATE = 0.02  # s of the server's work per second a client may use: 2 % of one core (a page: about 1.3 %)
BURST = 0.25  # s it may use at once (a page opening: the graph, the timeline, a history page)
REQUEST_COST = 0.001  # s charged per read besides its measured work (uvicorn's, FastAPI's)
HOLD = 1.0  # s a read over budget waits, to be answered (debt repaid by then) or refused (429)
SHARE = 4  # an address's clients of one role may together use this many clients' budget
MAX_CLIENTS = 10_000  # buckets kept; past this, the full ones (their clients idle) are forgotten

T = TypeVar("T")


@dataclass
class _Bucket:
    level: float  # seconds of work available at ``at`` (negative: owed)
    at: float  # monotonic time
    capacity: float
    rate: float  # seconds of work it gains per second

    def now(self, now: float) -> float:
        return min(self.capacity, self.level + (now - self.at) * self.rate)


class Meter:
    """What one read cost: the CPU time of the work it ran through ``run`` and ``in_thread``."""

    def __init__(self) -> None:
        self.seconds = 0.0

    def run(self, work: Callable[..., T], *args: Any) -> T:
        """``work(*args)`` here (on the loop), measured."""
        start = time.thread_time()
        try:
            return work(*args)
        finally:
            self.seconds += time.thread_time() - start

    async def in_thread(self, work: Callable[..., T], *args: Any) -> T:
        """``work(*args)`` in the thread pool, measured."""
        return await run_in_threadpool(self.run, work, *args)


class ReadBudget:
    """The buckets of every client (on the loop: not thread-safe)."""

    def __init__(self, rate: float = RATE, burst: float = BURST, hold: float = HOLD) -> None:
        self.rate = rate
        self.burst = burst
        self.hold = hold
        self._buckets: dict[Hashable, _Bucket] = {}

    def keys(self, address: str, role: str, page: str | None) -> tuple[Hashable, Hashable]:
        """The client's bucket and its address's (for its role)."""
        return (address, role, page), (address, role)

    def wait(self, keys: tuple[Hashable, Hashable]) -> float:
        """Seconds until every bucket of ``keys`` has paid its debt (0: now)."""
        now = time.monotonic()
        return max(0.0, *(-self._level(key, limit, now) / limit[1] for key, limit in zip(keys, self._limits())))

    def charge(self, keys: tuple[Hashable, Hashable], seconds: float) -> None:
        now = time.monotonic()
        for key, limit in zip(keys, self._limits()):
            self._buckets[key] = _Bucket(self._level(key, limit, now) - seconds, now, *limit)
        if len(self._buckets) > MAX_CLIENTS:
            self._forget_idle(now)

    def refusal(self, retry: int) -> str:
        """The 429's message for a client that may read again in ``retry`` seconds."""
        return ("too many reads: this client's budget of the server's time (%g %% of a core, %g s at once) is "
                "spent; retry after %d s" % (self.rate * 100, self.burst, retry))

    def _limits(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """(capacity, rate) of a client's bucket and of its address's."""
        return (self.burst, self.rate), (self.burst * SHARE, self.rate * SHARE)

    def _level(self, key: Hashable, limit: tuple[float, float], now: float) -> float:
        bucket = self._buckets.get(key)
        return limit[0] if bucket is None else bucket.now(now)

    def _forget_idle(self, now: float) -> None:
        for key in [key for key, bucket in self._buckets.items() if bucket.now(now) >= bucket.capacity]:
            del self._buckets[key]


def retry_after(wait: float) -> int:
    """Retry-After's whole seconds for a wait of ``wait`` seconds (at least 1)."""
    return max(1, math.ceil(wait))
