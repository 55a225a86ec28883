"""One IntrospectionServer's machine followed message by message: smach_ros's structures and statuses,
and the SMACH lines its node logs on /rosout, made into fsmscope's events (docs/interop.md says
what each tells). Bags (``smach_events.events``) and live streams feed the same ``Follower``.

One piece because the statuses and the lines tell the same run: a line says exactly what a
status only shows (an outcome, a self-transition, an end), and comes first (SMACH logs, then calls
the transition callbacks that publish the status), so each moves one model of what runs, and a
status that follows a line it agrees with adds only its userdata.

Order required: messages in the order of their stamps (a line is stamped when logged, a status
when published); messages a few milliseconds out of order across topics are merged by the
caller (``smach_events.in_time_order``), not here.
"""

from __future__ import annotations

from typing import Any, Callable

from fsm.observation import schema
from fsm.observation.encoding import dumps, encode_userdata
from fsm.observation.original_log import quiet
from fsm.observation.schema import build

from . import safe_pickle, smach_lines
from .bag_reader import Message
from .smach_tree import CONCURRENCE, ITERATOR, MACHINE, NONE, UNKNOWN, Tree, label, parent

WAIT = 2.5  # seconds of messages held until every container's structure came (each, every 2 to 2.1 s)
HELD = 100_000  # messages held at most while waiting
HEARTBEAT = "HEARTBEAT"  # the info of the status smach_ros's heartbeat thread publishes every 2 s
NOT_STEPS = (HEARTBEAT, "Initial state", "REMOTE_INIT", "")  # a status's info that is not a transition's
UNTOLD = {"$repr": "<not published yet>"}  # a key a start line names, whose value no status gave yet


IDLE_WAIT = 0.05  # s of stream a heartbeat that shows a running machine idle waits for its terminating line


class Follower:
    """The events of one server's machine (``server``, named ``machine``), one message at a time."""

    def __init__(self, server: str, machine: str) -> None:
        self.server, self.name = server, machine
        self.tree = Tree()
        self.described = -1  # the tree's version last described
        self.held: list[Message] = []  # before the first description
        self.refused: str | None = None  # why the schema refuses the structure: then no events
        self.active: dict[str, list[str]] = {}  # running containers -> their active states
        self.userdata: dict[str, dict] = {}  # container -> its userdata, last seen, encoded
        self.ended: dict[str, str] = {}  # container -> the outcome it last ended with
        self.pending: dict[str, int] = {}  # transitions told by lines whose status is yet to come
        self.inferred: dict[str, tuple[str, str]] = {}  # the last transition a status showed, per container
        self.returned: dict[str, dict[str, str]] = {}  # a running Concurrence's children's told outcomes
        self.closing: dict[str, dict[str, str]] = {}  # Concurrences whose end a line told, outcome untold yet
        self.lines = False  # whether SMACH's lines tell this machine
        self.idle_seen: dict[str, float] = {}  # running machines a heartbeat showed idle -> when (``_idle``)
        self.fresh: set[str] = set()  # containers seen idle, or just entered: a run of theirs starts at the start
        self.seq = self.runs = 0
        self.run: str | None = None
        self.t = 0.0
        self.finished: bool | None = None  # whether the last run's end is known (None: no run seen)
        self._out: list[dict] = []

    # The interface.
    def feed(self, m: Message) -> list[dict]:
        """The events ``m`` lets the follower tell, in order."""
        if self.refused is not None:
            return []
        self.t = max(self.t, m.t)
        if m.kind == "structure":
            self.tree.structure(m.fields)
        elif m.kind == "status":
            self.tree.status(m.fields)
        if self.described < 0:
            if len(self.held) < HELD:
                self.held.append(m)
            if self.tree.root is not None and m.t - self.held[0].t >= WAIT:
                self._release()
        else:
            self._apply(m)
        out, self._out = self._out, []
        return out if self.refused is None else []

    def end(self) -> list[dict]:
        """The stream ended: what can still be told (held messages, Concurrences whose end was told
        without their outcome); what still runs stays running."""
        if self.refused is None and self.described < 0 and self.tree.root is not None:
            self._release()
        self._end_idle(float("inf"))
        for path in sorted(self.closing, key=len, reverse=True):
            if path in self.closing:
                self._terminate(path, None)
        out, self._out = self._out, []
        return out if self.refused is None else []

    @property
    def root(self) -> str | None:
        """The root container's path, once a message named it."""
        return self.tree.root

    def event(self, make: Callable[..., dict], path: str, *fields: Any) -> dict:
        """An event another part adds to this machine's stream (a control asked of the robot): the
        next seq, at the time of the last message (the robot's clock, so the stream's times stay in order)."""
        self._event(make, path, *fields)
        return self._out.pop()

    # Describing the tree.
    def _release(self) -> None:
        held, self.held = self.held, []
        self.t = held[0].t if held else self.t
        self._describe()
        for m in held:
            if self.refused is None:
                self.t = max(self.t, m.t)
                self._apply(m)

    def _describe(self) -> None:
        self.described = self.tree.version
        self._event(build.structure, self.tree.root, self.tree.describe())
        problem = schema.validate(self._out[-1])
        if problem is not None:
            self.refused = problem

    def _apply(self, m: Message) -> None:
        self._end_idle(m.t)
        if self.tree.version != self.described:
            self._describe()
        if m.kind == "status":
            self._status(m.fields)
        elif m.kind == "log":
            said = smach_lines.read(m.fields["msg"], m.fields["level"])
            if said is not None:
                self._line(said)

    def _event(self, make: Callable[..., dict], path: str, *fields: Any) -> None:
        """The next event, made by the schema's maker of its kind (``schema.build``)."""
        self.seq += 1
        self._out.append(make(self.seq, self.t, self.run, self.name, path, *fields))

    # What a status shows.
    def _status(self, f: dict) -> None:
        path = f["path"]
        try:
            data = safe_pickle.local_data(f["local_data"]) if f["local_data"] else {}
        except ValueError as exc:
            data = {}
            self._event(build.log, path, "warn", "userdata not read: %s" % exc)
        data = encode_userdata(data if isinstance(data, dict) else {"local_data": data})
        active = [s for s in f["active_states"] if s != NONE]
        stepped = f["info"] not in NOT_STEPS  # published by a transition callback
        kind = self.tree.kind(path)
        if path not in self.active:
            if active:
                self._start_seen(path, f["initial_states"], active, data)
            else:
                self.fresh.add(path)
                self._userdata(path, data)
            return
        self._userdata(path, data)
        if kind == CONCURRENCE:
            self._concurrence_seen(path, active)
        elif not active:
            if self.lines and f["info"] == HEARTBEAT:
                self.idle_seen.setdefault(path, self.t)
            else:
                self._terminate(path, None)
        elif stepped and self.pending.get(path):
            self.pending[path] -= 1
            if active != self.active[path]:
                self._move(path, active[0], None)
        elif stepped or active != self.active[path]:
            source = self.active[path][0] if self.active[path] else ""
            self._move(path, active[0], None)
            self.inferred[path] = (source, active[0])

    def _end_idle(self, t: float) -> None:
        """End the machines a heartbeat showed idle ``IDLE_WAIT`` ago whose terminating line did not come.
        SMACH sets a machine's state to none, then logs the line that says how it ended
        (state_machine.py); smach_ros's heartbeat thread may publish between the two, stamped a moment
        before the line. Ended at once, the line would find no running machine and its outcome be lost."""
        for path, seen in list(self.idle_seen.items()):
            if path not in self.active:
                del self.idle_seen[path]
            elif t >= seen + IDLE_WAIT:
                del self.idle_seen[path]
                self._terminate(path, None)

    def _userdata(self, path: str, data: dict) -> None:
        old = self.userdata.get(path)
        self.userdata[path] = data
        if old is not None:
            changed = {k: v for k, v in data.items() if k not in old or dumps(old[k]) != dumps(v)}  # 1 is not True
            if changed:
                self._event(build.userdata, path, changed)

    def _start_seen(self, path: str, initial: list[str], active: list[str], data: dict) -> None:
        """A container a status shows running: a Concurrence with all its children (the others
        returned, what nothing told); a StateMachine from its initial state when that is where it
        is, or when it was seen idle or entered and one edge leads from there to where it is; else
        where it is (a recorder that joined late knows nothing of how it got there)."""
        initial = [s for s in initial if s != NONE] or active
        if self.tree.kind(path) == CONCURRENCE:
            self._start(path, initial, initial, data)
            self._concurrence_seen(path, active)
            return
        step = UNKNOWN
        if path in self.fresh and active != initial:
            step = self.tree.step(path, initial[0], active[0])
        if active == initial or step != UNKNOWN:
            self._start(path, initial, initial, data)
            if active != initial:
                self._move(path, active[0], step)
        else:
            self._start(path, initial, active, data)

    def _concurrence_seen(self, path: str, active: list[str]) -> None:
        """What a Concurrence's status shows, where no line tells it (with lines, a status may show a
        child gone before that child's line: children run at once)."""
        if self.lines:
            return
        running = self.active[path]
        if any(s not in running for s in active):  # it ran again
            self._terminate(path, None)
            self._start(path, self.tree.children(path), active, self.userdata.get(path, {}))
            return
        for child in [s for s in running if s not in active]:
            self._child_returned(path, child, self.returned.get(path, {}).get(child))

    # Starting, moving, ending.
    def _start(self, path: str, initial: list[str], active: list[str], data: dict) -> None:
        above = parent(path)
        if path != self.tree.root and above in self.tree.paths:
            if above not in self.active:  # where it is seen: a Concurrence runs all its children
                its_initial = self.tree.initial.get(above) or [label(path)]
                here = its_initial if self.tree.kind(above) == CONCURRENCE else [label(path)]
                self._start(above, its_initial, here, self.userdata.get(above, {}))
            elif label(path) not in self.active[above] and self.tree.kind(above) != CONCURRENCE:
                self._move(above, label(path), None)
        if path == self.tree.root:
            self.runs += 1
            self.run = "%s-%d" % (self.name, self.runs)
            self.finished = False
        self.active[path] = list(active)
        self.userdata[path] = data
        self.returned[path] = {}
        self.pending.pop(path, None)
        self.fresh.discard(path)
        if active == initial:
            self.fresh.update(path + "/" + s for s in active)
        self._event(build.start, path, list(initial), list(active), data)

    def _move(self, path: str, target: str, outcome: str | None) -> None:
        """A StateMachine's (or an Iterator's) state returned ``outcome`` (None: what the edges tell)."""
        if not self.active[path]:
            self.active[path] = [target]
            return
        source = self.active[path][0]
        told = outcome if outcome is not None else self.tree.step(path, source, target)
        outcome = self._leave(path, source, told)
        self.active[path] = [target]
        self.fresh.add(path + "/" + target)
        self._event(build.transition, path, source, outcome, target, [target])

    def _leave(self, path: str, state: str, outcome: str) -> str:
        """``state`` left its container ``path`` with ``outcome`` (UNKNOWN: untold): when it is a
        container still running, it ends with it; the outcome it ended with."""
        child = path + "/" + state
        if child in self.active or child in self.closing:
            self._terminate(child, None if outcome == UNKNOWN else outcome, tell_parent=False)
            return self.ended.get(child, UNKNOWN) if outcome == UNKNOWN else outcome
        return outcome

    def _child_returned(self, path: str, child: str, outcome: str | None) -> None:
        """A Concurrence's ``child`` returned ``outcome`` (None: untold)."""
        outcome = self._leave(path, child, outcome or UNKNOWN)
        self.returned.setdefault(path, {})[child] = outcome
        self.active[path] = [s for s in self.active[path] if s != child]
        self._event(build.transition, path, child, outcome, None, list(self.active[path]))

    def _terminate(self, path: str, outcome: str | None, state_outcome: str | None = None,
                   tell_parent: bool = True) -> None:
        """The container at ``path`` ended with ``outcome`` (None: what the edges tell, else UNKNOWN);
        ``tell_parent``: an Iterator above it goes on (its parent did not see it end)."""
        kind = self.tree.kind(path)
        running = self.active.pop(path, [])
        for state in running:
            if path + "/" + state in self.active or path + "/" + state in self.closing:
                told = state_outcome if kind != CONCURRENCE else self.returned.get(path, {}).get(state)
                self._leave(path, state, told or UNKNOWN)
        if kind == CONCURRENCE:
            told = self.closing.pop(path, None) or self.returned.get(path, {})
            outcomes = {c: told.get(c, UNKNOWN) for c in self.tree.children(path)}
            outcome = outcome or UNKNOWN
            self._event(build.terminate, path, self.tree.children(path), outcome, [], schema.ABSENT, outcomes)
        else:
            last = running or (self.tree.children(path)[:1] if kind == ITERATOR else [])
            returned = state_outcome or (self.ended.get(path + "/" + last[0]) if last else None)
            returned = None if returned == UNKNOWN else returned
            if last:
                outcome, state_outcome = self.tree.end(path, last[0], returned, outcome)
            outcome = outcome or UNKNOWN
            self._event(build.terminate, path, last, outcome, [],
                        schema.ABSENT if state_outcome is None else state_outcome)
        self.ended[path] = outcome
        self.returned.pop(path, None)
        self.fresh.add(path)
        if path == self.tree.root:
            self.finished = outcome != UNKNOWN
        above = parent(path)
        if tell_parent and self.tree.kind(above) == ITERATOR and above in self.active and outcome != UNKNOWN:
            self._iterated(above, label(path), outcome)

    def _iterated(self, path: str, body: str, outcome: str) -> None:
        """An Iterator's state returned ``outcome``: it loops (its edge back to it), or the Iterator
        ends (with the place its edge names, else the outcome itself)."""
        edges = self.tree.leaving(path, body)
        if any(e["outcome"] == outcome and e["to"] == body for e in edges):
            self.pending[path] = self.pending.get(path, 0) + 1
            self._event(build.transition, path, body, outcome, body, [body])
        elif any(e["outcome"] == outcome for e in edges):
            to = next(e["to"] for e in edges if e["outcome"] == outcome)
            self._terminate(path, to or outcome, outcome)

    # What a line says.
    def _line(self, said: smach_lines.Said) -> None:
        before = self.seq
        self._said(said)
        self.lines = self.lines or (said.kind != "other" and self.seq != before)

    def _said(self, said: smach_lines.Said) -> None:
        kind, v = said.kind, said.values
        if kind == "start":
            self._start_told(MACHINE, v[0], v[1])
        elif kind == "concurrence_start":
            self._start_told(CONCURRENCE, None, v[0])
        elif kind == "iterating":
            self._iterating(said)
        elif kind == "transition":
            self._transition_told(*v)
        elif kind == "terminate":
            self._terminate_told(*v)
        elif kind == "returned":
            path = self._one(lambda p: self.tree.kind(p) == CONCURRENCE and v[0] in self.active.get(p, ()))
            if path is not None:
                self._child_returned(path, v[0], v[1])
        elif kind == "outcomes":
            self._outcomes_told(v[0])
        elif kind == "serviced":
            path = self._one(lambda p: self.tree.kind(p) == CONCURRENCE and self.active.get(p) == []
                             and p not in self.closing)  # its children all returned (preempted) before
            if path is not None:
                self._event(build.log, path, said.level, said.text)
                self._terminate(path, "preempted")
        elif not quiet(said.level, said.text) and self.active:
            self._event(build.log, max(self.active, key=len), said.level, said.text)

    def _told(self, path: str, kind: str) -> None:
        """A line told the container's class: the tree is described again before its events."""
        self.tree.told(path, kind)
        if self.tree.version != self.described:
            self._describe()

    def _one(self, fits: Callable[[str], bool]) -> str | None:
        """The one container that ``fits``; None when none or several do (the line is then left untold)."""
        found = [p for p in self.tree.paths if fits(p)]
        return found[0] if len(found) == 1 else None

    def _enterable(self, path: str, again: bool = False) -> bool:
        """Not running (or, ``again``, running), and the root or a state its running parent is in."""
        above = parent(path)
        return (path in self.active) == again and (path == self.tree.root or label(path) in self.active.get(above, ()))

    def _of_kind(self, kind: str, fits: Callable[[str], bool]) -> str | None:
        """The one container of ``kind`` that ``fits``, else the one whose class nothing told yet that
        could be of that kind (a Concurrence has several children, an Iterator one)."""
        def could(p: str) -> bool:
            n = len(self.tree.children(p))
            return p not in self.tree.kinds and (n > 1 if kind == CONCURRENCE else n == 1)
        told = self._one(lambda p: self.tree.kinds.get(p) == kind and fits(p))
        return told or self._one(lambda p: could(p) and fits(p))

    def _start_told(self, kind: str, initial: str | None, keys: list[str]) -> None:
        if kind == MACHINE:
            if self._one(lambda p: self.tree.kind(p) == MACHINE and self.active.get(p) == [initial]):
                return  # a status showed it start first
            def fits(p: str) -> bool:
                return self.tree.kind(p) == MACHINE and self.tree.has(p, initial)
            path = self._one(lambda p: fits(p) and self._enterable(p))
            again = path or self._one(lambda p: fits(p) and self._enterable(p, again=True))
            if path is None and again is not None:  # it runs again, its last run's end untold
                self._terminate(again, None)
                path = again
        else:
            path = self._of_kind(CONCURRENCE, self._enterable)
        if path is None:
            return
        self._told(path, kind)
        above, own = self.userdata.get(parent(path), {}), self.userdata.get(path, {})
        data = {k: above[k] if k in above else own.get(k, UNTOLD) for k in keys}  # input keys: the parent's
        states = [initial] if initial is not None else self.tree.children(path)
        self._start(path, states, states, data)

    def _iterating(self, said: smach_lines.Said) -> None:
        path = self._of_kind(ITERATOR, lambda p: p in self.active) or self._of_kind(ITERATOR, self._enterable)
        if path is None:
            return
        self._told(path, ITERATOR)
        if path not in self.active:
            body = self.tree.children(path)
            self._start(path, body, body, self.userdata.get(path, {}))
        self._event(build.log, path, said.level, said.text)

    def _transition_told(self, source: str, outcome: str, target: str) -> None:
        def fits(p: str) -> bool:
            return self.tree.kind(p) == MACHINE and self.tree.has(p, target)
        path = self._one(lambda p: fits(p) and self.active.get(p) == [source])
        if path is None:
            seen = self._one(lambda p: fits(p) and self.active.get(p) == [target])
            if seen is not None and self.inferred.get(seen) == (source, target):  # its status came first
                self.pending[seen] = self.pending.get(seen, 0) + 1
                return
            path = self._one(lambda p: fits(p) and self.tree.has(p, source) and self._enterable(p))
            if path is None:
                return
            self._start(path, self.tree.initial.get(path) or [source], [source], self.userdata.get(path, {}))
        self._move(path, target, outcome)
        self.inferred.pop(path, None)
        self.pending[path] = self.pending.get(path, 0) + 1

    def _terminate_told(self, last: str, state_outcome: str, outcome: str) -> None:
        path = self._one(lambda p: self.tree.kind(p) == MACHINE and self.active.get(p) == [last]
                         and (outcome in self.tree.outcomes(p) or p not in self.tree.structures))
        if path is not None:
            self._terminate(path, outcome, state_outcome)

    def _outcomes_told(self, outcomes: dict[str, str | None] | None) -> None:
        path = self._one(lambda p: self.tree.kind(p) == CONCURRENCE and p in self.active and p not in self.closing
                         and (outcomes is None or set(outcomes) == set(self.tree.children(p))))
        if path is None:
            return
        told = {c: o for c, o in (outcomes or {}).items() if o is not None}
        for child in list(self.active[path]):
            self._child_returned(path, child, told.get(child))
        self.closing[path] = {**self.returned.get(path, {}), **told} if outcomes is None else {
            c: told.get(c, UNKNOWN) for c in outcomes}
