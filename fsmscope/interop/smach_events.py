"""smach_ros's introspection messages turned into fsmscope events (docs/interop.md says what a bag
cannot tell, and what this module infers instead).

An IntrospectionServer publishes a container's structure every 2 s and its status (active states,
userdata) when one of its states returns and every 2 s: no message says that a container started
or finished, or which outcome a state returned. Here each server's messages (``bag_reader.Message``,
in time order) become one machine's events:

- ``structure``: the tree from every container's first structure message (a container with none
  gets the states its statuses named); a container is a Concurrence when a status shows more than
  one initial or active state, else a StateMachine; a leaf's outcomes are those of its edges. Emitted once,
  before the first other event.
- ``start``: a container seen running (its active states not ``['None']``) that was not; the
  containers above it start first. A container first seen beyond its initial state starts there
  and moves on through ``transition`` events.
- ``transition``: the active states changed; the outcome is the one edge from the old state to
  the new, else "?" (several edges lead there, or none: the bag cannot tell).
- ``terminate``: a container seen idle again, or left by its parent's transition (whose edge
  names its outcome); else the outcome its last state's edges lead to, when only one.
- ``userdata``: the keys whose decoded value changed since the container's last status; values
  are decoded by ``safe_pickle`` (never run) and encoded as the runtime encodes them.
"""

from __future__ import annotations

import heapq
from typing import Any, Callable, Iterable, Iterator

from fsm.observation import names, schema
from fsm.observation.schema import build
from fsm.observation.encoding import dumps, encode_userdata

from . import safe_pickle
from .bag_reader import Message

UNKNOWN = "?"  # an outcome the bag does not tell
NONE = "None"  # what smach_ros writes for no state (idle container, an outcome with no transition)


def _parent(path: str) -> str:
    return path.rsplit("/", 1)[0]


def _label(path: str) -> str:
    return path.rsplit("/", 1)[1]


class _Tree:
    """The containers of one server, from its structure messages and what its statuses named; each
    container's edges, outcomes and edges by the state they leave made once, so that describing the
    tree and following a run take time in proportion to them."""

    def __init__(self, messages: list[Message]) -> None:
        self.structures: dict[str, dict] = {}
        self.named: dict[str, dict[str, None]] = {}  # container -> states its statuses named, in order
        self.initial: dict[str, list[str]] = {}
        self.concurrent: set[str] = set()
        for m in messages:
            f = m.fields
            if m.kind == "structure":
                self.structures.setdefault(f["path"], f)
                continue
            self.initial.setdefault(f["path"], [s for s in f["initial_states"] if s != NONE])
            states = self.named.setdefault(f["path"], {})
            for s in [*f["initial_states"], *f["active_states"]]:
                if s != NONE:
                    states[s] = None
            if len(f["active_states"]) > 1 or len(f["initial_states"]) > 1:  # a Concurrence starts them all
                self.concurrent.add(f["path"])
        self.paths = set(self.structures) | set(self.named)
        roots = sorted((p for p in self.paths if _parent(p) not in self.paths), key=len)
        self.root = roots[0] if roots else None
        self._edges: dict[str, list[dict]] = {}
        self._leaving: dict[str, dict[str, list[dict]]] = {}
        self._outcomes: dict[str, list[str]] = {}

    def edges(self, path: str) -> list[dict]:
        made = self._edges.get(path)
        if made is None:
            s = self.structures.get(path)
            made = self._edges[path] = [] if s is None else [
                schema.edge(f, o, None if t == NONE else t)
                for o, f, t in zip(s["internal_outcomes"], s["outcomes_from"], s["outcomes_to"])]
        return made

    def leaving(self, path: str, state: str) -> list[dict]:
        """The edges of the container at ``path`` from its child ``state``."""
        by_state = self._leaving.get(path)
        if by_state is None:
            by_state = self._leaving[path] = {}
            for e in self.edges(path):
                by_state.setdefault(e["from"], []).append(e)
        return by_state.get(state, [])

    def outcomes(self, path: str) -> list[str]:
        made = self._outcomes.get(path)
        if made is None:
            s = self.structures.get(path)
            made = self._outcomes[path] = sorted(s["container_outcomes"]) if s else []
        return made

    def children(self, path: str) -> list[str]:
        s = self.structures.get(path)
        return list(s["children"]) if s else list(self.named.get(path, {}))

    def node(self, path: str, depth: int = 0) -> dict:
        """The structure node of ``path``; nothing below the schema's deepest level is described (the
        schema then refuses the tree, with its words, and the recursion stays short)."""
        if path not in self.paths:
            outcomes = sorted({e["outcome"] for e in self.leaving(_parent(path), _label(path))})
            return schema.node(_label(path), path, "State", False, outcomes, [], [], {})
        node = schema.node(_label(path), path, "Concurrence" if path in self.concurrent else "StateMachine", True,
                           self.outcomes(path), [], [], {})
        children = [] if depth > schema.MAX_STRUCTURE_DEPTH else self.children(path)
        node.update(schema.container_fields(self.initial.get(path, []), self.edges(path),
                                            [self.node(path + "/" + c, depth + 1) for c in children]))
        return node

    def outcome(self, path: str, last: list[str], returned: list[str]) -> tuple[str, str | None]:
        """(the container's outcome, its last state's) from the edges of its last states into its
        outcomes (those of the outcomes they ``returned``, when known), when they name one; else UNKNOWN."""
        outcomes = self.outcomes(path)
        ends = {(e["to"], e["outcome"]) for state in dict.fromkeys(last) for e in self.leaving(path, state)
                if e["to"] in outcomes and (not returned or e["outcome"] in returned)}
        return next(iter(ends)) if len(ends) == 1 else (UNKNOWN, None)

    def step(self, path: str, source: str, target: str | None) -> str:
        """The outcome of the one edge from ``source`` to ``target`` (None: into an outcome), else UNKNOWN."""
        outcomes = self.outcomes(path)
        found = {e["outcome"] for e in self.leaving(path, source)
                 if e["to"] == target or (target is None and e["to"] in outcomes)}
        return found.pop() if len(found) == 1 else UNKNOWN


class _Machine:
    """One server's machine: what is running, and the events that say how it got there."""

    def __init__(self, name: str, tree: _Tree) -> None:
        self.name = name
        self.tree = tree
        self.active: dict[str, list[str]] = {}  # running containers -> their active states
        self.left: dict[str, list[str]] = {}  # container -> the states that left it last (its last ones)
        self.ended: dict[str, str] = {}  # container -> the outcome it terminated with, when known
        self.userdata: dict[str, dict] = {}  # container -> its userdata, last seen, encoded
        self.seq = 0
        self.runs = 0
        self.run: str | None = None
        self.t = 0.0

    def _event(self, make: Callable[..., dict], path: str, *fields: Any) -> dict:
        """The next event, made by the schema's maker of its kind (``schema.build``)."""
        self.seq += 1
        return make(self.seq, self.t, self.run, self.name, path, *fields)

    def structure(self) -> dict:
        return self._event(build.structure, self.tree.root, self.tree.node(self.tree.root))

    def status(self, m: Message) -> Iterator[dict]:
        self.t = m.t
        f = m.fields
        path = f["path"]
        try:
            data = safe_pickle.local_data(f["local_data"]) if f["local_data"] else {}
        except ValueError as exc:
            data = {}
            yield self._event(build.log, path, "warn", "userdata not read: %s" % exc)
        if not isinstance(data, dict):
            data = {"local_data": data}
        data = encode_userdata(data)  # compared and sent encoded: each value encoded once
        active = [s for s in f["active_states"] if s != NONE]  # an idle Concurrence's: none, not ['None']
        if path in self.active:
            yield from self._userdata(path, data)
            if f["active_states"] == [NONE]:
                yield from self._terminate(path, None)
            else:
                yield from self._move(path, active)
        elif active:
            yield from self._start(path, active, data)
        else:
            self.userdata[path] = data

    def _start(self, path: str, seen: list[str], data: dict) -> Iterator[dict]:
        parent = _parent(path)
        if path != self.tree.root and parent in self.tree.paths:
            if parent not in self.active:
                yield from self._start(parent, [_label(path)], self.userdata.get(parent, {}))
            elif _label(path) not in self.active[parent]:
                yield from self._move(parent, [_label(path)])
        if path == self.tree.root:
            self.runs += 1
            self.run = "%s-%d" % (self.name, self.runs)
        initial = self.tree.initial.get(path, []) or seen
        self.active[path] = list(initial)
        self.userdata[path] = data
        yield self._event(build.start, path, initial, list(initial), data)
        yield from self._move(path, seen)

    def _move(self, path: str, now: list[str]) -> Iterator[dict]:
        before = self.active[path]
        if now == before:
            return
        if path in self.tree.concurrent or len(before) > 1 or len(now) > 1:
            staying = set(now)
            left = [s for s in before if s not in staying]
            if left:
                self.left[path] = left
            gone: set[str] = set()
            for state in left:
                yield from self._leave(path, state, None)
                gone.add(state)
                remaining = [s for s in before if s not in gone]
                self.active[path] = remaining
                yield self._event(build.transition, path, state, self.tree.step(path, state, None), None, remaining)
            self.active[path] = list(now)
            return
        source = before[0] if before else None
        target = now[0] if now else None
        outcome = self.tree.step(path, source, target) if source is not None else UNKNOWN
        if source is not None:
            yield from self._leave(path, source, outcome)
            self.left[path] = [source]
        self.active[path] = list(now)
        if source is not None:
            yield self._event(build.transition, path, source, outcome, target, list(now))

    def _leave(self, path: str, state: str, outcome: str | None) -> Iterator[dict]:
        """A state its container left: when it is a running container, it terminated (with ``outcome``,
        the edge its parent took, when known)."""
        child = path + "/" + state
        if child in self.active:
            yield from self._terminate(child, outcome if outcome != UNKNOWN else None)

    def _terminate(self, path: str, outcome: str | None) -> Iterator[dict]:
        for child in [p for p in self.active if p.startswith(path + "/")]:
            if child in self.active:
                yield from self._terminate(child, None)
        last = self.active.pop(path) or self.left.get(path, [])
        known = [self.ended[path + "/" + s] for s in last if path + "/" + s in self.ended]
        own, state_outcome = self.tree.outcome(path, last, known)
        self.ended[path] = outcome = outcome or own
        yield self._event(build.terminate, path, last, outcome, [],
                          schema.ABSENT if state_outcome is None else state_outcome)

    def _userdata(self, path: str, data: dict) -> Iterator[dict]:
        old = self.userdata.get(path, {})
        changed = {k: v for k, v in data.items() if k not in old or dumps(old[k]) != dumps(v)}  # 1 is not True
        self.userdata[path] = data
        if changed:
            yield self._event(build.userdata, path, changed)


def events(messages: Iterable[Message], refused: Callable[[str], None] | None = None) -> Iterator[dict]:
    """fsmscope's events of every introspection server in ``messages`` (time order), one machine per
    server named after it (a ROS name made a machine's name: ``robot/arm`` becomes ``robot_arm``,
    fsm/observation/names.py); each machine's events in order, the machines' interleaved by time. A
    machine whose structure the schema refuses (too deep, a path too long, ...) has no events:
    ``refused`` hears why."""
    by_server: dict[str, list[Message]] = {}
    for m in messages:
        by_server.setdefault(m.server, []).append(m)
    streams = []
    taken: set[str] = set()
    for server, msgs in by_server.items():
        tree = _Tree(msgs)
        if tree.root is None:
            continue
        machine = _Machine(names.unique(server, taken), tree)
        machine.t = msgs[0].t
        structure = machine.structure()
        problem = schema.validate(structure)
        if problem is not None:
            if refused is not None:
                refused("machine %s, whose structure does not fit the schema: %s" % (machine.name, problem))
            continue
        taken.add(machine.name)
        streams.append(_machine_events(machine, structure, msgs))
    yield from _merge(streams)


def _machine_events(machine: _Machine, structure: dict, msgs: list[Message]) -> Iterator[dict]:
    yield structure
    for m in msgs:
        if m.kind == "status":
            yield from machine.status(m)


def _merge(streams: list[Iterator[dict]]) -> Iterator[dict]:
    yield from heapq.merge(*streams, key=lambda ev: ev["t"])
