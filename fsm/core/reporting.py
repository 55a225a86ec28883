"""The runtime's reporting seam: what a container tells whoever observes it, and nothing of how.

Core imports no extension (pytransitions' rule): ``fsm.observation`` implements ``Reporter`` and
binds one to each state of an observed tree (``state._reporter``, None otherwise, which costs one
``is None`` test per step). Core calls one method per event kind, with plain values; the observer
encodes and stamps them. Also here, because core keeps them and observers read them: the thread's
current (reporter, path), for the log lines a state writes; the hooks run when a top-level container
starts; the construction generation, which says when a described structure may be stale; and the
mark that an error was already reported.
"""

from __future__ import annotations

import sys
import threading
import traceback
from typing import Any, Callable, Protocol

class Reporter(Protocol):
    """What core calls on an observed state's ``_reporter`` (implemented by fsm.observation.introspection);
    its calls never raise: observing a machine never changes what it does."""

    root: Any  # the top-level container it reports for

    def begin_run(self) -> None:
        """The root container starts a run."""

    def start(self, path: str, initial: list[str], active: list[str], userdata: Any) -> None:
        """The container at ``path`` began executing; ``userdata`` is its UserData."""

    def transition(self, path: str, from_: str, outcome: str, to: str | None, active: list[str],
                   changes: dict | None = None) -> None:
        """A child of the container at ``path`` returned ``outcome``; ``to``: the next child (None in a
        Concurrence); ``changes``: the keys of the container's userdata the step wrote, with their values."""

    def terminate(self, path: str, last: list[str], outcome: str | None, active: list[str] = ...,
                  state_outcome: str | None = ..., outcomes: dict = ..., error: str | None = ...,
                  changes: dict | None = None) -> None:
        """The container at ``path`` finished (``outcome`` None: without one); ``changes`` as a transition's."""

    def userdata(self, path: str, written: dict) -> None:
        """Keys of the container's userdata written since they were last reported, with their values,
        when no transition or terminate of the container carries them (a debugger's hold)."""

    def preempt(self, path: str, phase: str) -> None:
        """A preempt was 'requested' of, or 'serviced' by, the state at ``path``."""

    def error(self, path: str, state: Any, exc: BaseException) -> None:
        """``exc`` ended the container at ``path``; ``state``: the child's label that raised, if known."""


# The thread's innermost observed container: (reporter, path), for the log lines written inside it.
_context = threading.local()
NOT_ENTERED = object()


def enter(rep: Reporter, path: str) -> Any:
    """Mark ``path`` as the innermost observed container running on this thread; returns what to restore."""
    prev = getattr(_context, "current", None)
    _context.current = (rep, path)
    return prev


def enter_once(ctx: tuple[Reporter, str]) -> Any:
    """``enter`` with the (reporter, path) made once, by whoever enters it at every step: nothing to
    do (``NOT_ENTERED``) when it is the current one already (a child running inside its container)."""
    prev = getattr(_context, "current", None)
    if prev is ctx:
        return NOT_ENTERED
    _context.current = ctx
    return prev


def leave(prev: Any) -> None:
    if prev is not NOT_ENTERED:
        _context.current = prev


def current() -> tuple[Reporter, str] | None:
    """The (reporter, path) of the innermost observed container running on this thread, if any."""
    return getattr(_context, "current", None)


# Hooks run as a top-level container starts, before its first event (a debugger, a recorder per machine).
Hook = Callable[[Any], None]
top_level_hooks: list[Hook] = []


def add_global_hook(hook: Hook) -> None:
    """``hook(container)`` runs whenever a top-level container starts executing, before its first event."""
    top_level_hooks.append(hook)


def remove_global_hook(hook: Hook) -> None:
    if hook in top_level_hooks:
        top_level_hooks.remove(hook)


def on_top_level_start(container: Any) -> None:
    for hook in list(top_level_hooks):
        try:
            hook(container)
        except Exception:
            sys.stderr.write("fsm: a global introspection hook failed:\n" + traceback.format_exc())


# Bumped by every construction call anywhere: a structure described before it may be stale.
_generation = 0


def structure_changed() -> None:
    """A container was built or changed: the next run of every observed machine re-describes it."""
    global _generation
    _generation += 1


def structure_generation() -> int:
    return _generation


def carry_reported(error: BaseException, cause: BaseException) -> BaseException:
    """``error`` wraps ``cause``: when an ``error`` event already described ``cause``, none is sent for ``error``."""
    if getattr(cause, "_fsm_reported", False):
        error._fsm_reported = True  # type: ignore[attr-defined]
    return error


def mark_reported(exc: BaseException) -> bool:
    """Mark ``exc`` as described by an ``error`` event; False when it already was."""
    if getattr(exc, "_fsm_reported", False):
        return False
    try:
        exc._fsm_reported = True  # type: ignore[attr-defined]
    except AttributeError:
        pass
    return True
