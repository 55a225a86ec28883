"""Statistics of a recorded run: outcome, visits and time per state, transitions taken, errors.

``Summary`` takes events one at a time (so a followed log can be summarised as it grows)
and gives a JSON-safe dict (``to_dict``) or a text table (``format``). A state is active
from the event that makes it active (its container's ``start``, or the ``transition`` to
it) to the event that ends it (the ``transition`` from it, or its container's
``terminate``); a visit still open when the log ends counts as a visit without a time.
A machine's duration is the time its runs took (root ``start`` to root ``terminate``; a run
still open when the log ends, to its last event); the idle time between runs is apart.
"""

from __future__ import annotations

import statistics
from array import array
from typing import Any, Iterable

from .structure_index import StructureIndex

FINISHED = "finished"  # the root container ended with an outcome
ERROR = "error"  # it ended without one (an exception, a failed check, a shutdown)
INCOMPLETE = "incomplete"  # the log ends while it runs (the process died), or it never started


class _Machine:
    def __init__(self, name: str) -> None:
        self.name = name
        self.root_path: str | None = None
        self.runs = 0
        self.events = 0
        self.first_t: float | None = None
        self.last_t: float | None = None
        self.outcome: str | None = None
        self.status = INCOMPLETE
        self.ended_with_error: str | None = None
        self.visits: dict[str, int] = {}
        self.durations: dict[str, array] = {}  # seconds of each visit that ended (an array: a long run has millions)
        self.last_outcome: dict[str, str] = {}  # state path -> the outcome it last returned
        self.times: dict[str, tuple[int, dict]] = {}  # state path -> (visits timed, ``time_in``'s answer for them)
        self.entered: dict[str, dict[str, float | None]] = {}  # container path -> {label: entered at}
        self.transitions: dict[tuple[str, str, str, str | None], int] = {}
        self.errors: list[dict] = []
        # preempt events: "requested" of any container (the machine's own are "of_machine"), "serviced" by any state
        self.preempts = {"requested": 0, "serviced": 0, "of_machine": 0}
        self.feedback = 0
        self.controls: list[dict] = []
        self.run_time = 0.0  # of the runs that ended
        self.run_start: float | None = None  # when the open run started
        self.run_end: float | None = None  # when the last run ended
        self.idle = 0.0  # between runs
        self.run: str | None = None  # the run of the last event
        self.left: set[str] = set()  # runs whose events were followed by another run's
        self.last_seq: int | None = None
        self.interleaved = 0  # events that came back to a run already left, or did not follow their run's seq

    def written(self, run: str | None, seq: int | None) -> None:
        """An event of ``run`` numbered ``seq``: one that comes back to a run the log had left, or does
        not follow its run's last seq, was written by a second writer at once (two processes
        recording into one file): its runs' events interleave."""
        if run is None:  # before the machine's first run: no run to follow
            pass
        elif run != self.run:
            if run in self.left:
                self.interleaved += 1
            if self.run is not None:
                self.left.add(self.run)
            self.run = run
        elif seq is not None and self.last_seq is not None and seq <= self.last_seq:
            self.interleaved += 1
        self.last_seq = seq

    def start_run(self, t: float | None) -> None:
        if self.run_start is not None:  # the log never ended the run before: it ends at its last event
            self.end_run(self.last_t)
        if self.run_end is not None and t is not None:
            self.idle += max(0.0, t - self.run_end)
        self.runs += 1
        self.run_start = t

    def end_run(self, t: float | None) -> None:
        if self.run_start is not None and t is not None:
            self.run_time += max(0.0, t - self.run_start)
        self.run_start, self.run_end = None, t

    def duration(self) -> float | None:
        """Seconds of running, a run still open counting to the last event; None before any run."""
        if not self.runs:
            return None
        if self.run_start is None or self.last_t is None:
            return self.run_time
        return self.run_time + max(0.0, self.last_t - self.run_start)

    def enter(self, path: str, label: str, t: float | None) -> None:
        self.entered.setdefault(path, {})[label] = t
        state = path + "/" + label
        self.visits[state] = self.visits.get(state, 0) + 1

    def leave(self, path: str, label: str, t: float | None) -> None:
        started = self.entered.get(path, {}).pop(label, None)
        if started is not None and t is not None:
            self.durations.setdefault(path + "/" + label, array("d")).append(max(0.0, t - started))

    def leave_all(self, path: str, t: float | None) -> None:
        for label in list(self.entered.get(path, {})):
            self.leave(path, label, t)

    def took(self, path: str, frm: str, outcome: str, to: str | None) -> None:
        """State ``frm`` of container ``path`` returned ``outcome``, leading to ``to``."""
        key = (path, frm, outcome, to)
        self.transitions[key] = self.transitions.get(key, 0) + 1
        self.last_outcome[path + "/" + frm] = outcome

    def state(self, state: str) -> dict:
        """The statistics of one state path: visits, seconds (total, median, max, last), last outcome."""
        return {"visits": self.visits.get(state, 0), "time": self.time_in(state),
                "last_outcome": self.last_outcome.get(state)}

    def time_in(self, state: str) -> dict:
        """Seconds in ``state``: total, median, max, last; computed once per number of visits timed (a
        server asks again and again, and the median sorts them all)."""
        times = self.durations.get(state, ())
        known = self.times.get(state)
        if known is None or known[0] != len(times):
            known = self.times[state] = (len(times), {
                "total": sum(times), "median": statistics.median(times) if times else None,
                "max": max(times) if times else None, "last": times[-1] if times else None})
        return dict(known[1])

    def sync(self, path: str, active: list[str], t: float | None) -> None:
        current = self.entered.get(path, {})
        for label in list(current):
            if label not in active:
                self.leave(path, label, t)
        for label in active:
            if label not in current and label != "None":
                self.enter(path, label, t)


class Summary:
    """Accumulates the statistics of any number of machines from their events."""

    def __init__(self, structures: StructureIndex | None = None) -> None:
        self.structures = structures or StructureIndex()
        self._own_structures = structures is None
        self.machines: dict[str, _Machine] = {}
        self.events = 0
        self.problems: list[Any] = []

    def add(self, event: dict) -> None:
        kind = event["kind"]
        if kind == "snapshot":
            if self._own_structures:
                self.structures.apply(event)
            return
        self.events += 1
        name = event["machine"]
        m = self.machines.get(name)
        if m is None:
            m = self.machines[name] = _Machine(name)
        m.events += 1
        m.written(event.get("run"), event.get("seq"))
        t = event.get("t")
        if m.first_t is None:
            m.first_t = t
        path = event["path"]
        if kind == "structure":
            if self._own_structures:
                self.structures.apply(event)
            m.root_path = path
        elif kind == "start":
            if path == m.root_path or m.root_path is None:
                m.root_path = path
                m.start_run(t)
                m.status, m.outcome, m.ended_with_error = INCOMPLETE, None, None
            m.leave_all(path, t)
            m.sync(path, list(event.get("active") or []), t)
        elif kind == "transition":
            frm = event.get("from")
            m.took(path, str(frm), str(event.get("outcome")), event.get("to"))
            if frm is not None:
                m.leave(path, frm, t)
            m.sync(path, list(event.get("active") or []), t)
        elif kind == "terminate":
            m.leave_all(path, t)
            outcome = event.get("outcome")
            last = event.get("last") or []
            if outcome is not None and self.structures.container_type(event) != "Concurrence" and last:
                m.took(path, str(last[0]), str(event.get("state_outcome", outcome)), str(outcome))
            if path == m.root_path:
                m.end_run(t)
                m.outcome = outcome
                m.status = FINISHED if outcome is not None else ERROR
                m.ended_with_error = event.get("error")
        elif kind == "error":
            m.errors.append({"t": t, "path": path, "state": event.get("state"), "exc_type": event.get("exc_type"),
                             "message": event.get("message")})
        elif kind == "preempt":
            phase = event.get("phase")
            if phase in ("requested", "serviced"):
                m.preempts[phase] += 1
                if phase == "requested" and path == m.root_path:
                    m.preempts["of_machine"] += 1
        elif kind == "feedback":
            m.feedback += 1
        elif kind == "control":
            m.controls.append({k: event.get(k) for k in ("t", "action", "reason", "client", "result")})
        m.last_t = t  # after the event: a run it starts closes one left open at the event before

    def add_all(self, events: Iterable[dict]) -> Summary:
        for event in events:
            self.add(event)
        return self

    # Results.
    def state(self, machine: str, state: str) -> dict:
        """One state's statistics (``_Machine.state``); no visits and no times for one not seen."""
        return self.machines.get(machine, _Machine(machine)).state(state)

    def exit_code(self) -> int:
        """0: every machine finished with an outcome; 1: one ended in an error, never finished, or its
        events were written by two processes at once;
        2: not one event (the log is empty or unreadable, which is not a run that failed)."""
        if not self.machines:
            return 2
        return 0 if all(m.status == FINISHED and not m.interleaved for m in self.machines.values()) else 1

    def to_dict(self) -> dict:
        machines = {}
        for name, m in self.machines.items():
            states = {state: m.state(state) for state in m.visits}
            machines[name] = {
                "status": m.status, "outcome": m.outcome, "error": m.ended_with_error, "runs": m.runs,
                "events": m.events, "started": m.first_t, "ended": m.last_t,
                "duration": m.duration(), "idle": m.idle,
                "states": states,
                "transitions": [{"path": p, "from": f, "outcome": o, "to": to, "count": c}
                                for (p, f, o, to), c in m.transitions.items()],
                "errors": m.errors, "preempts": dict(m.preempts), "feedback": m.feedback, "controls": m.controls,
                "interleaved": m.interleaved}
        return {"events": self.events, "machines": machines, "exit_code": self.exit_code(),
                "problems": [{"line": p.line, "message": p.message} for p in self.problems]}

    def format(self) -> str:
        data = self.to_dict()
        out = []
        if not data["machines"]:
            out.append("no events")
        for name, m in data["machines"].items():
            if m["status"] == FINISHED:
                head = "finished with outcome '%s'" % m["outcome"]
            elif m["status"] == ERROR:
                head = "ended in an error: %s" % (m["error"] or "no outcome")
            else:
                head = "did not finish (the log ends while it runs)"
            duration = "" if m["duration"] is None else " after %.3f s running" % m["duration"]
            idle = ", %.3f s idle between runs" % m["idle"] if m["runs"] > 1 else ""
            out.append("machine %s: %s%s (%d run%s, %d events%s)"
                       % (name, head, duration, m["runs"], "" if m["runs"] == 1 else "s", m["events"], idle))
            if m["states"]:
                width = max(len("state"), *(len(s) for s in m["states"]))
                out.append("  %-*s %7s %10s %10s %10s" % (width, "state", "visits", "total s", "median s", "max s"))
                for state, info in sorted(m["states"].items()):
                    tm = info["time"]
                    out.append("  %-*s %7d %10s %10s %10s" % (width, state, info["visits"], _sec(tm["total"]),
                                                             _sec(tm["median"]), _sec(tm["max"])))
            if m["transitions"]:
                out.append("  transitions taken:")
                for tr in sorted(m["transitions"], key=lambda tr: (tr["path"], -tr["count"])):
                    to = "(done)" if tr["to"] is None else tr["to"]
                    out.append("    %s: %s --%s--> %s  x%d" % (tr["path"], tr["from"], tr["outcome"], to, tr["count"]))
            if m["interleaved"]:
                out.append("  written by two processes at once: %d event%s out of their run's order (two runs' "
                           "events interleave in this log; each process should record to a file of its own)"
                           % (m["interleaved"], "" if m["interleaved"] == 1 else "s"))
            if m["preempts"]["requested"] or m["preempts"]["serviced"]:
                out.append("  preempts: " + _preempts(m["preempts"]))
            if m["errors"]:
                out.append("  errors:")
                for err in m["errors"]:
                    state = " in state '%s'" % err["state"] if err["state"] else ""
                    message = (str(err["message"] or "").strip().splitlines() or [""])[0]
                    out.append("    %s%s: %s: %s" % (err["path"], state, err["exc_type"], message))
            else:
                out.append("  errors: none")
        if data["problems"]:
            out.append("%d line%s skipped (see above)" % (len(data["problems"]), "" if len(data["problems"]) == 1 else "s"))
        return "\n".join(out)


def _preempts(counts: dict) -> str:
    """The preempts of a machine in words. One preempt of the machine is serviced by each state it
    reaches (the running leaf, then each container around it, as SMACH's containers do), and a container
    preempts its own children too (a Concurrence whose child ends it, the debugger forcing an outcome):
    the preempt events requested and serviced are not counts of one thing."""
    serviced = counts["serviced"]
    times = "%d time%s" % (serviced, "" if serviced == 1 else "s")
    if counts["of_machine"]:
        return ("%d asked of the machine, serviced %s (by each state and container a preempt reaches, the running "
                "state first)" % (counts["of_machine"], times))
    return ("none asked of the machine; serviced %s inside it (a container preempts its own children: a Concurrence "
            "when one of them ends it, the debugger when it forces an outcome)" % times)


def _sec(value: float | None) -> str:
    return "-" if value is None else "%.4f" % value


def summarize(events: Iterable[dict]) -> Summary:
    return Summary().add_all(events)
