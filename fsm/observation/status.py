"""The state of one machine, rebuilt from its events: what a snapshot holds and a viewer shows.

One reducer serves the recorder's snapshots, replay and the server's hub, so that a
replayed run and a live one cannot disagree.
"""

from __future__ import annotations

import copy
from typing import Any, Sequence

from .structure import containers


def _container_entry(initial: list[str] | None = None) -> dict:
    return {"active": [], "initial": list(initial or []), "userdata": {}, "running": False, "outcome": None,
            "last": None, "changes": {}, "written": False}


def _write(entry: dict, written: dict) -> None:
    """Keys of the container's userdata were written (a ``userdata`` event, or the ``changes`` a
    transition or terminate carries, applied before it): the values, and what its next transition changed."""
    userdata = entry["userdata"]
    if not entry.get("written"):
        entry["changes"], entry["written"] = {}, True
    changes = entry["changes"]
    for key, new in written.items():
        change = changes.get(key)
        if change is None:
            change = changes[key] = {"old": userdata[key]} if key in userdata else {}
        change["new"] = new
    userdata.update(written)


def _settle(entry: dict, last: dict | None) -> None:
    """The container left a state: its last transition is ``last``, and the keys written since the
    previous one are what this one changed (none when nothing was written)."""
    if not entry.get("written"):
        entry["changes"] = {}
    entry["written"] = False
    entry["last"] = last


def _last_of_run(events: Sequence[dict], i: int, event: dict, entry: dict) -> tuple[dict, int]:
    """``event``, a transition, and those of the same container that follow it at once in ``events``
    (from ``i``), in the same run: a machine stepping fast. Each one's writes go into the userdata,
    and only the last is left for the caller to settle the container with: what the others settled
    is replaced by it (its changes' old values are read after theirs). Returns (the last, where the
    events after it start)."""
    path, run, n = event["path"], event.get("run"), len(events)
    nxt = events[i]
    if nxt["kind"] != "transition" or nxt["path"] != path or nxt.get("run") != run:
        return event, i
    userdata = entry["userdata"]
    while True:
        written = event.get("changes")
        if written is not None:
            userdata.update(written)
        event, i = nxt, i + 1
        if i == n:
            break
        nxt = events[i]
        if nxt["kind"] != "transition" or nxt["path"] != path or nxt.get("run") != run:
            break
    entry["written"] = False  # as the transition before the last left it
    return event, i


class Status:
    """Per machine: structure, and per container path its active/initial states, userdata, outcome,
    last transition and the userdata keys that transition changed (old and new values); the robot's pose."""

    def __init__(self, machine: str) -> None:
        self.machine = machine
        self.run: str | None = None
        self.root_path: str | None = None
        self.structure: dict | None = None
        self.containers: dict[str, dict] = {}
        self.running = False
        self.outcome: str | None = None
        self.error: dict | None = None
        self.last_seq = 0
        self.last_t: float | None = None
        self.run_seq = 0  # the seq of the current run's first event: where its history starts
        # A preempt requested and not over yet: {"seq", "t", "path", "serviced": [paths that serviced it]}.
        self.preempt: dict | None = None
        self.pose: dict | None = None  # the last pose event's {seq, t, joints, bodies}
        self.debug: dict | None = None  # the debugger's {mode, level, holds, breakpoints}, from its events

    def apply(self, event: dict) -> None:
        self.apply_all((event,))

    def apply_all(self, events: Sequence[dict]) -> None:
        """Apply events in order: a batch of them (fsm/observation/delivery.py), in one loop whose
        every step of a running machine (a transition and the writes it carries, a userdata event)
        is written out here; the transitions of one container that follow each other are folded as
        one (``_last_of_run``)."""
        containers = self.containers
        run = self.run
        i, n = 0, len(events)
        step = None  # the last event applied, when it is a step's: the seq and time the Status is at
        while i < n:
            event = events[i]
            i += 1
            kind = event["kind"]
            path = event["path"]
            if event.get("run", run) != run:
                run = self.run = event["run"]
                self.run_seq = event["seq"]
            if kind == "transition" or kind == "userdata":
                entry = containers.get(path)
                if entry is None:
                    entry = containers[path] = _container_entry()
                if kind == "transition" and i < n:
                    event, i = _last_of_run(events, i, event, entry)
                written = event.get("changes")  # a userdata event's, or those its step's transition carries
                if written is not None:
                    _write(entry, written)
                if kind == "transition":
                    entry["active"] = event["active"]  # events are never changed once emitted: no copy
                    _settle(entry, {"from": event["from"], "outcome": event["outcome"], "to": event["to"],
                                    "seq": event["seq"]})
                step = event
                continue
            step = None
            self.last_seq, self.last_t = event["seq"], event.get("t")
            self._apply_other(event, kind, path)
            containers, run = self.containers, self.run  # a snapshot or a structure replaces them
        if step is not None:
            self.last_seq, self.last_t = step["seq"], step.get("t")

    def _apply_other(self, event: dict, kind: str, path: str) -> None:
        """Every kind but a step's: a run's start and end, the structure, a snapshot, a preempt, the
        debugger, an error, the robot's pose."""
        if kind == "snapshot":
            self._load(event["status"])
            return
        if kind == "structure":
            self._set_structure(path, event["root"])
            return
        if kind == "preempt":
            self._preempt(event)
            return
        if kind == "pose":
            self.pose = {"seq": event["seq"], "t": event["t"], "joints": event["joints"],
                         "bodies": event.get("bodies", {})}
            return
        if kind == "debug":
            self._debug(event)
            return
        if kind not in ("start", "terminate", "error"):
            return
        entry = self.containers.get(path)
        if entry is None:
            entry = self.containers[path] = _container_entry()
        root = path == self.root_path
        if kind == "start":
            if root:  # a new run: what the previous one reached no longer describes the machine
                self.running, self.outcome, self.error, self.preempt = True, None, None, None
                if self.debug is not None:  # a run never starts holding
                    self.debug["holds"] = []
                for other in self.containers.values():
                    other.update(active=[], running=False, outcome=None, last=None, changes={}, written=False)
            entry.update(active=list(event["active"]), initial=list(event["initial"]),
                         userdata=dict(event["userdata"]), running=True, outcome=None, last=None, changes={},
                         written=False)
        elif kind == "terminate":
            written = event.get("changes")
            if written is not None:
                _write(entry, written)
            last = event["last"]
            state_outcome = event.get("state_outcome")
            _settle(entry, {"from": last[0], "outcome": state_outcome, "to": event["outcome"], "seq": event["seq"]}
                    if len(last) == 1 and state_outcome else entry.get("last"))
            entry.update(active=[], running=False, outcome=event["outcome"])
            if root:
                self.running, self.outcome, self.preempt = False, event["outcome"], None
                if event.get("error") and self.error is None:
                    self.error = {"path": path, "message": event["error"]}
        elif kind == "error":
            self.error = {k: event.get(k) for k in ("path", "state", "exc_type", "message", "traceback")}

    def _preempt(self, event: dict) -> None:
        if event["phase"] == "requested":
            if self.preempt is None and self.running:
                self.preempt = {"seq": event["seq"], "t": event["t"], "path": event["path"], "serviced": []}
        elif self.preempt is not None:
            self.preempt["serviced"].append(event["path"])

    def _debug(self, event: dict) -> None:
        """Mode, holds and breakpoints as the debugger's events say (a hold ends with its release)."""
        debug = self.debug
        if debug is None:
            debug = self.debug = {"mode": "run", "level": None, "holds": [], "breakpoints": []}
        action = event["action"]
        if action == "mode":
            debug["mode"], debug["level"] = event["mode"], event.get("level")
        elif action == "breakpoints":
            debug["breakpoints"] = event["breakpoints"]
        elif action == "hold":
            debug["mode"], debug["level"] = "pause", None
            debug["holds"] = debug["holds"] + [{
                "path": event["path"], "state": event["state"], "at": event["at"], "outcome": event.get("outcome"),
                "reason": event["reason"], "detail": event["detail"], "seq": event["seq"]}]
        elif action == "release":
            held = [h for h in debug["holds"] if h["path"] == event["path"] and h["state"] == event["state"]]
            debug["holds"] = [h for h in debug["holds"] if h is not held[0]] if held else debug["holds"]

    def preempt_waiting_on(self) -> list[str]:
        """The active states that have not serviced the pending preempt (none when there is none)."""
        if self.preempt is None:
            return []
        serviced = set(self.preempt["serviced"])
        return [p for p in self.active_leaves() if p not in serviced]

    def active_leaves(self) -> list[str]:
        """The full paths of the active states that are not containers themselves."""
        active = [path + "/" + label for path, entry in self.containers.items() for label in entry["active"]
                  if label != "None"]
        return [p for p in active if p not in self.containers]

    def _set_structure(self, path: str, root: dict) -> None:
        self.root_path = path
        self.structure = root
        previous = self.containers
        self.containers = {}
        for node in containers(root):
            entry = previous.get(node["path"]) or _container_entry()
            entry["initial"] = list(node.get("initial", []))
            self.containers[node["path"]] = entry

    def to_dict(self) -> dict:
        return {"machine": self.machine, "run": self.run, "root_path": self.root_path, "structure": self.structure,
                "containers": copy.deepcopy(self.containers), "running": self.running, "outcome": self.outcome,
                "error": self.error, "last_seq": self.last_seq, "last_t": self.last_t, "run_seq": self.run_seq,
                "preempt": None if self.preempt is None else dict(self.preempt, serviced=list(self.preempt["serviced"])),
                "pose": self.pose, "debug": copy.deepcopy(self.debug)}

    def _load(self, data: dict) -> None:
        self.run = data.get("run")
        self.root_path = data.get("root_path")
        self.structure = data.get("structure")
        self.containers = copy.deepcopy(data.get("containers") or {})
        self.running = bool(data.get("running"))
        self.outcome = data.get("outcome")
        self.error = data.get("error")
        self.last_seq = data.get("last_seq", self.last_seq)
        self.last_t = data.get("last_t", self.last_t)
        self.run_seq = data.get("run_seq", 0)
        self.preempt = copy.deepcopy(data.get("preempt"))
        self.pose = data.get("pose")
        self.debug = copy.deepcopy(data.get("debug"))
        for entry in self.containers.values():  # a snapshot of an older fsmscope lacks these
            entry.setdefault("last", None)
            entry.setdefault("changes", {})
            entry.setdefault("written", False)

    @classmethod
    def from_dict(cls, data: dict) -> Status:
        status = cls(data["machine"])
        status._load(data)
        return status


def rebuild(events: Any) -> dict[str, Status]:
    """Apply a stream of events of any number of machines; returns one Status per machine."""
    statuses: dict[str, Status] = {}
    for event in events:
        machine = event["machine"]
        status = statuses.get(machine)
        if status is None:
            status = statuses[machine] = Status(machine)
        status.apply(event)
    return statuses
