"""Watching a machine built with the original SMACH (ros/executive_smach: the noetic-devel core or
its ros2 branch's), in process, with the events of an fsm machine (docs/events.md) and without
changing what it does.

fsm imports nothing of ``smach``: such a machine is told by its shape (``is_original``: a container
by SMACH's interface that is not one of fsm's). ``OriginalReporter`` is the ``Reporter`` of one:
describing the tree (children, edges, initial states, outcomes, keys, remappings, read through the
containers' own interface) also hooks each state that is not hooked yet, once:

- every container's start, transition and termination callbacks, as smach_ros's
  IntrospectionServer registers them (original_container.ContainerWatch);
- each state's ``execute``, for what nothing else tells: the outcome it returned (unless its
  container's edges tell it), what it raised, the debugger's gates; a container's
  ``request_preempt`` and every state's ``service_preempt``; each replaced on the instance by a
  call of the same method (original_container.Watched, PreemptWatched);
- SMACH's log functions, at each run's start (original_log).

A machine is described again at the start of a run whose tree differs from the one last described
(a cheap signature of the tree: a state added, an initial state set), as fsm does with its
construction generation.
"""

from __future__ import annotations

import sys
import uuid
from typing import Any

from ..core.state import State
from . import original_log
from .introspection import Reporter, _never_raising, describe_node, foreign_reporters
from .original_container import ContainerWatch, PreemptWatched, Watched
from .schema import build
from .structure import children, is_concurrence, is_container


def is_original(machine: Any) -> bool:
    """A container of the original SMACH (or any container by SMACH's interface that is not fsm's)."""
    return not isinstance(machine, State) and is_container(machine) and hasattr(machine, "register_start_cb")


def smach_package(machine: Any) -> Any:
    """The ``smach`` package the machine's classes come from (its log functions live there), or None."""
    for cls in type(machine).__mro__:
        if "register_start_cb" in vars(cls):
            module = sys.modules.get(cls.__module__)
            package = getattr(module, "smach", None)
            if package is None:
                package = sys.modules.get(cls.__module__.rpartition(".")[0])
            return package
    return None


class OriginalReporter(Reporter):
    """The reporter of a machine of the original SMACH: describes it by reading it, hooking it as it goes."""

    def __init__(self, root: Any, machine: str, root_path: str) -> None:
        super().__init__(root, machine, root_path)
        self._package = smach_package(root)
        self._signature: tuple | None = None  # the tree's signature when it was last described
        self._entered = False  # the root's execute (wrapped) began this run

    @_never_raising
    def begin_run(self) -> None:
        """A new run id, SMACH's log functions wrapped, then the structure if the tree changed since
        it was last sent (or an observer joined since)."""
        self.run = uuid.uuid4().hex[:12]
        if self._package is not None:
            original_log.watch(self._package)
        signature = tree_signature(self.root)
        if self._described_at == -1 or signature != self._signature:
            self._described_at = 0
            self.send(build.structure, self.root_path, self.structure())

    def structure(self) -> dict:
        """Hook every state of the tree not hooked yet, bind it to this reporter and describe it."""
        label = self.root_path.rstrip("/").rsplit("/", 1)[-1] or "SM_ROOT"
        self._signature = tree_signature(self.root)
        return _describe(self.root, label, self.root_path, self, None, {})

    # The root's run: begun by its wrapped execute, or by its start callback when it was called
    # through a method taken before it was watched (a machine attached while it runs).
    def root_entered(self) -> None:
        self._entered = True
        self.begin_run()

    def root_started(self) -> None:
        if not self._entered:
            self.begin_run()

    def root_left(self) -> None:
        self._entered = False


def tree_signature(root: Any) -> tuple:
    """What a description depends on that can change after construction, cheaply: each container's
    children, initial states and edges (which of its children's outcomes its edges tell)."""
    parts = []
    stack = [root]
    while stack:
        state = stack.pop()
        if not is_container(state):
            continue
        below = children(state)
        parts.append((id(state), tuple(map(id, below.values())), tuple(map(str, below)),
                      tuple(map(str, state.get_initial_states())), tuple(map(tuple, state.get_internal_edges()))))
        stack.extend(below.values())
    return tuple(parts)


def _describe(state: Any, label: str, path: str, rep: OriginalReporter, parent: ContainerWatch | None,
              remapping: dict) -> dict:
    own = _hook(state, rep, path, parent, label, is_container(state))
    node = describe_node(state, label, path, remapping,
                         lambda child, lbl, at, remap: _describe(child, lbl, at, rep, own, remap))
    if not node["container"]:
        return node
    if is_concurrence(state):
        default = getattr(state, "_default_outcome", None)
        node.update(default_outcome=None if default is None else str(default),
                    outcome_map={str(co): {str(k): str(v) for k, v in m.items()}
                                 for co, m in (getattr(state, "_outcome_map", None) or {}).items()})
    elif hasattr(state, "_exhausted_outcome"):  # an Iterator
        node["exhausted_outcome"] = str(state._exhausted_outcome)
    return node


def _hook(state: Any, rep: OriginalReporter, path: str, parent: ContainerWatch | None, label: str,
          container: bool) -> ContainerWatch | None:
    """Bind ``state`` to ``rep`` at ``path`` (hooking it the first time); returns its own watch if a
    container. A state that takes no attribute (``__slots__``) is described, not watched."""
    try:
        state._reporter = rep
        state._path = path
    except AttributeError:
        return None
    own = None
    if container:
        own = getattr(state, "_fsm_watch", None)
        if own is None:
            own = state._fsm_watch = ContainerWatch(state)
            state._report_changes = own.report_changes  # what fsm's debugger calls before a hold
        own.bind(rep, path, path == rep.root_path)
        if getattr(state, "_debugger", None) is None:  # found at each child's step, not looked for in vain
            state._debugger = None
    watched = Watched.of(state)
    watched.parent, watched.label, watched.own, watched.root = parent, label, own, path == rep.root_path
    state.execute = watched.leaf if own is None and parent is not None and label in parent.told else watched
    for name, phase in (("request_preempt", "requested"), ("service_preempt", "serviced")):
        method = getattr(state, name, None)
        if method is not None and not isinstance(method, PreemptWatched) and (container or phase == "serviced"):
            setattr(state, name, PreemptWatched(state, method, phase))
    return own


def attach(machine: Any, name: str, path: str) -> OriginalReporter | None:
    """A reporter for a machine of the original SMACH, its tree hooked and bound to it (None for
    another machine): what ``fsm.attach`` makes for one."""
    if not is_original(machine):
        return None
    rep = OriginalReporter(machine, name, path)
    rep.structure()
    return rep


foreign_reporters.append(attach)
