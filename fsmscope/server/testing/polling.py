"""Waiting for a condition that another thread or process makes true: the one polling loop of
the tests and the tooling."""

from __future__ import annotations

import time
from typing import Callable, TypeVar

T = TypeVar("T")


def wait_for(predicate: Callable[[], T], timeout: float = 5.0, interval: float = 0.005,
             what: str | Callable[[], str] | None = None) -> T:
    """Call ``predicate`` every ``interval`` s until it returns a truthy value, and return that value.

    After ``timeout`` s raises TimeoutError naming what it waited for: ``what`` (a callable is called
    then, so the message can show the state at the end), else the predicate's name. An exception
    of ``predicate`` propagates: a predicate may give up early."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() >= deadline:
            named = what() if callable(what) else what or getattr(predicate, "__qualname__", repr(predicate))
            raise TimeoutError("waited %.1f s for %s" % (timeout, named))
        time.sleep(interval)
