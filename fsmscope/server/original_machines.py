"""The top-level machines of the original smach, found as they start, for ``fsmscope run``.

fsm tells a global hook of each top-level machine (``fsm.add_global_hook``); the original has no
such hook, so for one run the ``execute`` of its container classes (StateMachine, and Sequence
through it; Concurrence; Iterator) is wrapped to tell ``found`` of a container that is not part of
a machine found before: a nested container executes inside its parent, and is one of its
descendants. The wrapper calls the original ``execute`` with what it was given and returns what it
returns; ``found`` raising is said on stderr and never reaches the machine.
"""

from __future__ import annotations

import sys
import threading
import traceback
from types import ModuleType
from typing import Any, Callable

CONTAINER_CLASSES = ("StateMachine", "Concurrence", "Iterator")


def _descendants(container: Any) -> dict[int, Any]:
    """``container`` and every state below it, by id."""
    found = {id(container): container}
    stack = [container]
    while stack:
        children = getattr(stack.pop(), "get_children", None)
        for child in (children() if children is not None else {}).values():
            if id(child) not in found:
                found[id(child)] = child
                stack.append(child)
    return found


class OriginalMachines:
    """Watches one original smach module's containers until ``stop``."""

    def __init__(self, smach: ModuleType, found: Callable[[Any], None]) -> None:
        self._found = found
        self._lock = threading.Lock()
        self._machines: list[Any] = []
        self._known: dict[int, Any] = {}  # the machines found and their descendants, held so no id is reused
        self._wrapped: list[tuple[type, Any]] = []
        for name in CONTAINER_CLASSES:
            cls = getattr(smach, name, None)
            if isinstance(cls, type) and "execute" in cls.__dict__:
                self._wrapped.append((cls, cls.__dict__["execute"]))
                cls.execute = self._wrap(cls.__dict__["execute"])

    def _wrap(self, execute: Callable[..., Any]) -> Callable[..., Any]:
        starting = self._starting

        def watched_execute(container: Any, *args: Any, **kwargs: Any) -> Any:
            starting(container)
            return execute(container, *args, **kwargs)
        watched_execute.__wrapped__ = execute  # type: ignore[attr-defined]
        watched_execute.__name__ = watched_execute.__qualname__ = execute.__name__
        watched_execute.__doc__ = execute.__doc__
        return watched_execute

    def _starting(self, container: Any) -> None:
        if id(container) in self._known:
            return
        with self._lock:
            for machine in self._machines:  # a state may have been added since it was found
                self._known.update(_descendants(machine))
            if id(container) in self._known:
                return
            self._machines.append(container)
            self._known.update(_descendants(container))
        try:
            self._found(container)
        except Exception:
            sys.stderr.write("fsmscope: cannot watch a machine of the original smach:\n" + traceback.format_exc())

    def stop(self) -> None:
        """Give the classes their own ``execute`` back."""
        for cls, execute in self._wrapped:
            cls.execute = execute
        self._wrapped.clear()
