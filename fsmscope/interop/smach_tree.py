"""One introspection server's container tree, as its messages tell it, growing as they come.

A structure message gives a container's children, edges and outcomes (the latest one counts); a
status gives its initial states and the states it names. Neither names a container's class: a
status of an idle container tells it (a StateMachine reports ``['None']``, a Concurrence or an
Iterator no state; a Concurrence lists all its children as initial states, a StateMachine one of
them; an Iterator has the one child, whose loop outcomes lead back to it; only a StateMachine has
an edge from a child to another), and so do SMACH's lines ("Concurrence starting",
"Iterating"). Until then a container is a StateMachine.

What the edges tell of an outcome: a StateMachine's and an Iterator's edges are every outcome of
every child (SMACH binds an unmapped outcome to 'None', the container outcome of the same name), so
the one edge from a state to where it went tells the outcome it returned. A Concurrence's edges are
its outcome map, which names only some of its children's outcomes: they tell nothing of an outcome.
"""

from __future__ import annotations

from fsm.observation import schema

UNKNOWN = "?"  # an outcome nothing told
NONE = "None"  # smach_ros's word for no state: an idle StateMachine, an outcome with no transition
MACHINE, CONCURRENCE, ITERATOR = "StateMachine", "Concurrence", "Iterator"


def parent(path: str) -> str:
    return path.rsplit("/", 1)[0]


def label(path: str) -> str:
    return path.rsplit("/", 1)[1]


class Tree:
    """The containers of one server; ``version`` grows whenever their description changes."""

    def __init__(self) -> None:
        self.structures: dict[str, dict] = {}
        self.named: dict[str, dict[str, None]] = {}  # container -> states its statuses named, in order
        self.initial: dict[str, list[str]] = {}
        self.kinds: dict[str, str] = {}  # containers whose class was told
        self.paths: set[str] = set()
        self.version = 0
        self._leaving: dict[str, dict[str, list[dict]]] = {}
        self._labels: dict[str, frozenset[str]] = {}

    # What the messages tell.
    def structure(self, f: dict) -> None:
        path = f["path"]
        if self.structures.get(path) != f:
            self.structures[path] = f
            self._leaving.pop(path, None)
            self._changed(path)
            children = set(f["children"])
            if any(a == b for a, b in zip(f["outcomes_from"], f["outcomes_to"])) and len(children) == 1:
                self.kinds[path] = ITERATOR  # its one child's outcome leading back to it: an Iterator's loop
            elif any(a != b and b in children for a, b in zip(f["outcomes_from"], f["outcomes_to"])):
                self.kinds[path] = MACHINE  # an edge from a child to another: only a StateMachine's

    def status(self, f: dict) -> None:
        path = f["path"]
        initial = [s for s in f["initial_states"] if s != NONE]
        named = self.named.setdefault(path, {})
        new = [s for s in [*initial, *f["active_states"]] if s != NONE and s not in named]
        for s in new:
            named[s] = None
        if self.initial.get(path) != initial or (new and path not in self.structures) or path not in self.paths:
            self.initial[path] = initial
            self._changed(path)
        if f["active_states"] == [NONE] or (len(initial) == 1 and len(self.children(path)) > 1):
            self.told(path, MACHINE)  # idle; or one initial state of several (a Concurrence's are all)
        elif len(initial) > 1 or len(f["active_states"]) > 1:
            self.told(path, CONCURRENCE)
        elif not f["active_states"] and self.kinds.get(path) != ITERATOR:
            self.told(path, CONCURRENCE)  # idle and no 'None': a Concurrence, or an Iterator its edges tell

    def told(self, path: str, kind: str) -> None:
        if self.kinds.get(path) != kind:
            self.kinds[path] = kind
            self._changed(path)

    def _changed(self, path: str) -> None:
        self._labels.pop(path, None)
        self.paths.add(path)
        self.version += 1

    # What it is.
    @property
    def root(self) -> str | None:
        roots = sorted((p for p in self.paths if parent(p) not in self.paths), key=len)
        return roots[0] if roots else None

    def kind(self, path: str) -> str:
        return self.kinds.get(path, MACHINE)

    def children(self, path: str) -> list[str]:
        s = self.structures.get(path)
        return list(s["children"]) if s else list(self.named.get(path, {}))

    def has(self, path: str, state: str) -> bool:
        """Whether ``state`` is a child of the container at ``path`` (a set made once per change)."""
        labels = self._labels.get(path)
        if labels is None:
            labels = self._labels[path] = frozenset(self.children(path))
        return state in labels

    def outcomes(self, path: str) -> list[str]:
        s = self.structures.get(path)
        return list(s["container_outcomes"]) if s else []

    def edges(self, path: str) -> list[dict]:
        s = self.structures.get(path)
        return [] if s is None else [schema.edge(f, o, None if t == NONE else t)
                                     for o, f, t in zip(s["internal_outcomes"], s["outcomes_from"], s["outcomes_to"])]

    def leaving(self, path: str, state: str) -> list[dict]:
        """The edges of the container at ``path`` from its child ``state``."""
        by_state = self._leaving.get(path)
        if by_state is None:
            by_state = self._leaving[path] = {}
            for e in self.edges(path):
                by_state.setdefault(e["from"], []).append(e)
        return by_state.get(state, [])

    def describe(self) -> dict:
        return self.node(self.root)

    def node(self, path: str, depth: int = 0) -> dict:
        """The structure node of ``path``; nothing below the schema's deepest level is described (the
        schema then refuses the tree, with its words, and the recursion stays short)."""
        if path not in self.paths:
            outcomes = sorted({e["outcome"] for e in self.leaving(parent(path), label(path))})
            return schema.node(label(path), path, "State", False, outcomes, [], [], {})
        node = schema.node(label(path), path, self.kind(path), True, sorted(self.outcomes(path)), [], [], {})
        children = [] if depth > schema.MAX_STRUCTURE_DEPTH else self.children(path)
        node.update(schema.container_fields(self.initial.get(path, []), self.edges(path),
                                            [self.node(path + "/" + c, depth + 1) for c in children]))
        return node

    # What the edges tell (never of a Concurrence's children: its edges are its outcome map).
    def step(self, path: str, source: str, target: str) -> str:
        """The outcome ``source`` returned to go to its sibling ``target``: that of the one edge between them."""
        if self.kind(path) == CONCURRENCE:
            return UNKNOWN
        found = {e["outcome"] for e in self.leaving(path, source) if e["to"] == target}
        return found.pop() if len(found) == 1 else UNKNOWN

    def end(self, path: str, last: str, returned: str | None, outcome: str | None = None) -> tuple[str, str]:
        """(the container's outcome, what its last state returned) when the container ended after
        ``last`` (which ``returned`` its outcome, and the container ended with ``outcome``, when
        known): a unique place out of the container among the edges from ``last`` decides the
        first, a unique edge the second; else UNKNOWN."""
        if self.kind(path) == CONCURRENCE:
            return outcome or UNKNOWN, returned or UNKNOWN
        outcomes = self.outcomes(path)
        ends = set()
        for e in self.leaving(path, last):  # SMACH's rule: a target that is no state nor outcome falls through
            place = e["to"] if e["to"] in outcomes else e["outcome"]
            if (not self.has(path, e["to"]) and place in outcomes and returned in (None, e["outcome"])
                    and outcome in (None, place)):
                ends.add((place, e["outcome"]))
        places = {place for place, _ in ends}
        place = places.pop() if len(places) == 1 else UNKNOWN
        return outcome or place, returned or (ends.pop()[1] if len(ends) == 1 else UNKNOWN)
