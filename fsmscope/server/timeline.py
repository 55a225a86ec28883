"""One machine's timeline: which child each container had active when, the instants worth a tick
(errors, preempt requests, operator controls, run starts) and the seqs to step through; what
GET /api/machines/{name}/timeline answers (docs/api.md, "Timeline").

``TimelineIndex.add_all`` sees every event of its machine, in batches in the delivery's thread
(``Feed.take_batch``) or one at a time on the loop (``Feed.apply``), one caller at a time: only start/transition/terminate events add
a mark, error/preempt/control events a tick, the others cost a dict lookup. ``answer`` runs in
any thread while events keep coming: storage is appended to or replaced whole, never changed in
place, and a reader takes a list's length before reading it.

Memory is bounded: past ``MAX_MARKS`` transitions the older half is coalesced into
``COARSE_BUCKETS`` buckets (several states within one bucket become one "…" band) and
``kept_from`` says from which seq the detail is whole.
"""

from __future__ import annotations

from array import array
from bisect import bisect_left, bisect_right
from itertools import chain, compress, islice
from operator import itemgetter, le, ne
from struct import pack
from typing import Sequence

from fsm.logfiles.transcript import debug_message
from fsm.observation.vocabularies import EVENT_TICK_KINDS, RUN_TICK

MAX_MARKS = 1_000_000     # transitions kept in full detail (per machine) before the older half is coalesced
COARSE_BUCKETS = 10_000   # buckets the coalesced part keeps
MAX_TICKS = 100_000       # ticks (and run starts) kept, newest first
MAX_LISTED = 5000         # ticks, runs and transitions in one answer, at most
TEXT_LIMIT = 200          # characters of a tick's text
SEVERAL = "+"             # a Concurrence with several children running
MANY = "…"                # several states within one bucket

_MARKS = frozenset(("start", "transition", "terminate"))
_TICKS = frozenset(EVENT_TICK_KINDS)
_DEBUG_TICKS = frozenset(("mode", "hold", "forced"))  # a release follows every hold: its tick would say nothing new
_KIND, _PATH, _T, _SEQ, _ACTIVE, _FIRST = (itemgetter(key) for key in ("kind", "path", "t", "seq", "active", 0))
_NO_LABEL = object()  # before a track's first mark: unequal to every label


class _Track:
    """One container's marks: from ``t[i]`` (event ``seq[i]``) its active child was ``label[i]``
    (None: not running), until the next mark. Adjacent labels always differ."""

    __slots__ = ("t", "seq", "label")

    def __init__(self, t: array | None = None, seq: array | None = None, label: list | None = None) -> None:
        self.t = array("d") if t is None else t
        self.seq = array("q") if seq is None else seq
        self.label: list[str | None] = [] if label is None else label


def _extend(column: array, values: list) -> None:
    """``column.extend(values)`` at a third of its cost: an array's ``extend`` parses each item as a call's
    argument, ``struct.pack`` converts them in one pass."""
    column.frombytes(pack("%d%s" % (len(values), column.typecode), *values))


def _bands(track: _Track, lo: float, hi: float, width: float, end: float) -> list[list]:
    """``[t0, t1, seq0, label]`` for the part of ``track`` within [lo, hi]; a mark's band ends at the
    next mark (the last one at ``end``). A band shorter than ``width`` starts a "…" band ``width``
    long (the marks within it), after which the last of those marks goes on; adjacent "…" merge, so
    every band but the first and last is at least ``width`` long: at most (hi - lo) / width + 2."""
    labels = track.label
    n = len(labels)  # first: ``add_all`` appends to t and seq before label
    ts, seqs = track.t, track.seq
    stop = bisect_right(ts, hi, 0, n)
    i = max(bisect_right(ts, lo, 0, stop) - 1, 0)
    out: list[list] = []
    floor = lo  # where the current mark's band starts when a "…" band took its beginning
    while i < stop:
        start = max(ts[i], floor)
        nxt = ts[i + 1] if i + 1 < n else end
        if nxt - start >= width or i + 1 >= stop:
            band, i = [start, min(nxt, hi), seqs[i], labels[i]], i + 1
            if band[1] <= start and i < stop:  # an empty band, not the last
                continue
        else:  # the marks starting within [start, start + width) make one "…" band; the last goes on after it
            cut = min(start + width, hi)
            k = max(bisect_left(ts, cut, i + 1, stop), i + 2)  # at least one mark on, even when cut is hi
            band, i, floor = [start, cut, seqs[i], MANY], k - 1, cut
        if out and out[-1][3] == band[3]:
            out[-1][1] = band[1]
        else:
            out.append(band)
    return out


def _tick_text(event: dict, kind: str) -> str | None:
    """What a tick says (None: this event is not one, e.g. a preempt being serviced)."""
    if kind == "error":
        state = event.get("state")
        text = "%s%s: %s" % (state + ": " if state else "", event["exc_type"], event["message"])
    elif kind == "preempt":
        if event["phase"] != "requested":
            return None
        text = "preempt requested of " + event["path"]
    elif kind == "debug":
        if event["action"] not in _DEBUG_TICKS:
            return None
        text = debug_message(event)[1]
    else:
        result, reason = event["result"], event.get("reason")
        text = event["action"] + ("" if result == "accepted" else " (%s)" % result) + (": " + reason if reason else "")
    return text if len(text) <= TEXT_LIMIT else text[:TEXT_LIMIT - 1] + "…"


class TimelineIndex:
    """One machine's timeline, updated with every event (``add_all``), answered by ``answer``."""

    def __init__(self) -> None:
        self.first: tuple[int, float] | None = None
        self.last: dict | None = None  # the last event seen
        self.kept_from: tuple[int, float] | None = None  # (seq, t) from which the detail is whole, once coalesced
        self._tracks: dict[str, _Track] = {}
        self._steps = (array("q"), array("d"))  # seq and t of every start/transition/terminate, in order
        self._ticks: list[tuple[int, float, str, str]] = []
        self._runs: list[tuple[str, int, float]] = []
        self._run: str | None = None
        self._clock = float("-inf")  # the latest t marked: marks never go back in time (a wall clock may)

    def add(self, event: dict) -> None:
        """One event of the machine, after those it was given before."""
        self.add_all((event,))

    def add_all(self, events: Sequence[dict]) -> None:
        """Events of the machine, in order (a batch of them, fsmscope/server/feed.py). A mark is the
        hot path (every step of a running machine), written out here rather than split into calls:
        each call costs the machine."""
        if not events:
            return
        if self.last is None:
            self.first = (events[0]["seq"], events[0]["t"])
        self.last = events[-1]
        kinds = list(map(_KIND, events))
        if len(kinds) > 1 and kinds.count("transition") == len(kinds) and self._add_steps(events):
            return
        tracks = self._tracks
        clock = self._clock
        seqs: list[int] = []  # the marks' seqs and times, and each track's new marks: put in the arrays at the end
        ts: list[float] = []
        marks: dict[str, list] = {}  # path -> [times, seqs, labels, its track, the last label]
        for event, kind in zip(events, kinds):
            if kind not in _MARKS:
                if kind in _TICKS:
                    text = _tick_text(event, kind)
                    if text is not None:
                        self._clock = clock
                        self._tick(event["seq"], self._now(event["t"]), kind, text)
                        clock = self._clock
                elif kind == "structure":
                    self._clock = clock
                    self._check_run(event)
                    clock = self._clock
                continue
            if kind == "start":
                self._clock = clock
                self._check_run(event)
                clock = self._clock
            t = event["t"]
            if t < clock:
                t = clock
            else:
                clock = t
            path = event["path"]
            new = marks.get(path)
            if new is None:
                track = tracks.get(path)
                if track is None:
                    track = tracks[path] = _Track()
                new = marks[path] = [[], [], [], track, track.label[-1] if track.label else _NO_LABEL]
            if kind == "terminate":
                label = None
            else:
                active = event["active"]
                label = active[0] if len(active) == 1 else (SEVERAL if active else None)
            seq = event["seq"]
            seqs.append(seq)
            ts.append(t)
            if new[4] != label:
                new[0].append(t)
                new[1].append(seq)
                new[2].append(label)
                new[4] = label
        self._clock = clock
        step_seqs, step_ts = self._steps
        _extend(step_seqs, seqs)
        _extend(step_ts, ts)
        for times, marked, labels, track, _ in marks.values():
            if labels:
                _extend(track.t, times)
                _extend(track.seq, marked)
                track.label.extend(labels)
        if len(step_seqs) > MAX_MARKS:
            self._coalesce()

    def _add_steps(self, events: Sequence[dict]) -> bool:
        """A batch of transitions of one container, each with one active state, at times that never go
        back: a machine stepping fast, marked with C's loops rather than Python's (what ``add_all`` does
        one event at a time, at about half its cost). False, having done nothing, for any other batch."""
        path = events[0]["path"]
        paths = list(map(_PATH, events))
        ts = list(map(_T, events))
        actives = list(map(_ACTIVE, events))
        if paths.count(path) != len(paths) or ts[0] < self._clock or not all(map(le, ts, islice(ts, 1, None))) \
                or set(map(len, actives)) != {1}:
            return False
        seqs = list(map(_SEQ, events))
        labels = list(map(_FIRST, actives))
        step_seqs, step_ts = self._steps
        _extend(step_seqs, seqs)
        _extend(step_ts, ts)
        track = self._tracks.get(path)
        if track is None:
            track = self._tracks[path] = _Track()
        changed = list(map(ne, labels, chain((track.label[-1] if track.label else _NO_LABEL,), labels)))
        if changed.count(True) == len(changed):  # a loop's states, each differing from the one before
            _extend(track.t, ts)
            _extend(track.seq, seqs)
            track.label.extend(labels)
        else:
            _extend(track.t, list(compress(ts, changed)))
            _extend(track.seq, list(compress(seqs, changed)))
            track.label.extend(compress(labels, changed))
        self._clock = ts[-1]
        if len(step_seqs) > MAX_MARKS:
            self._coalesce()
        return True

    def _now(self, t: float) -> float:
        """``t``, or the latest time marked when the wall clock went back."""
        if t < self._clock:
            return self._clock
        self._clock = t
        return t

    def _check_run(self, event: dict) -> None:
        run = event.get("run")
        if run is not None and run != self._run:
            self._run = run
            seq, t = event["seq"], self._now(event["t"])
            self._runs.append((run, seq, t))
            if len(self._runs) > MAX_TICKS:
                self._runs = self._runs[-MAX_TICKS // 2:]
            self._tick(seq, t, RUN_TICK, "run " + run)

    def _tick(self, seq: int, t: float, kind: str, text: str) -> None:
        self._ticks.append((seq, t, kind, text))
        if len(self._ticks) > MAX_TICKS:
            self._ticks = self._ticks[-MAX_TICKS // 2:]

    def _coalesce(self) -> None:
        """Keep the newer half of the transitions whole; the older half becomes COARSE_BUCKETS buckets."""
        seqs, ts = self._steps
        half = len(seqs) // 2
        start, cut = ts[0], ts[half]
        width = (cut - start) / COARSE_BUCKETS
        kept = sorted({bisect_left(ts, start + k * width, 0, half) for k in range(COARSE_BUCKETS)})
        self._steps = (array("q", [seqs[i] for i in kept]) + seqs[half:], array("d", [ts[i] for i in kept]) + ts[half:])
        for path, track in list(self._tracks.items()):
            old = bisect_left(track.t, cut)
            if old <= 2 * COARSE_BUCKETS:
                continue
            bands = _bands(_Track(track.t[:old], track.seq[:old], track.label[:old]), start, cut, width, cut)
            self._tracks[path] = _Track(array("d", [b[0] for b in bands]) + track.t[old:],
                                        array("q", [b[2] for b in bands]) + track.seq[old:],
                                        [b[3] for b in bands] + track.label[old:])
        self.kept_from = (seqs[half], cut)

    def answer(self, since_t: float | None = None, until_t: float | None = None, buckets: int = 1000) -> dict:
        """The timeline of [since_t, until_t] (default: the whole run) at ``buckets`` bands per container."""
        first, last = self.first, self.last
        if first is None or last is None:
            return {"first": None, "last": None, "kept_from": 0, "runs": [], "bands": {}, "ticks": [],
                    "transitions": [], "coarse": False}
        end = max(last["t"], self._clock)
        lo = first[1] if since_t is None else since_t
        hi = end if until_t is None else min(until_t, end)
        width = max(hi - lo, 0.0) / buckets
        bands = {}
        for path, track in list(self._tracks.items()):
            found = _bands(track, lo, hi, width, end)
            if found:
                bands[path] = found
        seqs, ts = self._steps
        n = min(len(ts), len(seqs))
        a, b = bisect_left(ts, lo, 0, n), bisect_right(ts, hi, 0, n)
        picked = (range(a, b) if b - a <= MAX_LISTED
                  else (a + round(k * (b - 1 - a) / (MAX_LISTED - 1)) for k in range(MAX_LISTED)))
        kept = self.kept_from
        return {"first": {"seq": first[0], "t": first[1]}, "last": {"seq": last["seq"], "t": end},
                "kept_from": first[0] if kept is None else kept[0],
                "runs": [{"run": r, "seq": s, "t": t} for r, s, t in self._in_range(self._runs, 2, lo, hi, True)],
                "bands": bands,
                "ticks": [{"seq": s, "t": t, "kind": k, "text": x} for s, t, k, x in
                          self._in_range(self._ticks, 1, lo, hi, False)],
                "transitions": [[seqs[i], ts[i]] for i in picked],
                "coarse": b - a > MAX_LISTED or (kept is not None and lo < kept[1])}

    @staticmethod
    def _in_range(items: list[tuple], at: int, lo: float, hi: float, with_current: bool) -> list[tuple]:
        """The newest MAX_LISTED of ``items`` (ordered by their element ``at``, a time) within [lo, hi];
        ``with_current``: also the one in force at ``lo`` (the run under way there)."""
        a = bisect_left(items, lo, key=lambda item: item[at])
        b = bisect_right(items, hi, key=lambda item: item[at])
        if with_current and a > 0 and (a == len(items) or items[a][at] > lo):
            a -= 1
        return items[max(a, b - MAX_LISTED):b]
