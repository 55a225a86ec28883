"""Observers closed at interpreter exit: a script that ends without closing its recorder or its
publisher still gets its last events written or sent. Held weakly: a closed or dropped observer
is not kept alive."""

from __future__ import annotations

import atexit
import weakref
from typing import Protocol


class Closable(Protocol):
    def close(self) -> None: ...


_open: weakref.WeakSet[Closable] = weakref.WeakSet()


def close_at_exit(observer: Closable) -> None:
    """Close ``observer`` when the interpreter exits, unless ``closed`` is called for it first."""
    _open.add(observer)


def closed(observer: Closable) -> None:
    """``observer`` closed itself: nothing to do for it at exit."""
    _open.discard(observer)


@atexit.register
def _close_all() -> None:
    for observer in list(_open):
        try:
            observer.close()
        except Exception:
            pass
