"""A container's userdata in a machine of the original SMACH, as last reported: what changed since.

The original's ``UserData`` keeps no record of writes (fsm's tracks the keys written), so a change
is told by comparing encoded values: at a container's start every key is encoded and kept; at each
transition and termination every key is encoded again and the keys whose encoding differs (or that
are new) are the change. A value that is the very same immutable object as last time (a str, an int,
...), or one of built-in types whose ``marshal`` bytes are those of last time, is not encoded again
(``marshal`` is C, and runs no user code: what smach_ros pays per transition for its pickle). The userdata is only read, through its ``_data`` dict (read-only; reading
``ud._dirty`` or any other missing ``_`` name of the original raises inside its ``__getattr__``).
"""

from __future__ import annotations

import marshal
from typing import Any

from .encoding import _key, encode

# Values whose identity says they did not change: the same object cannot have changed in place.
_IMMUTABLE = frozenset((str, int, float, bool, type(None), bytes, complex))


def _fingerprint(value: Any) -> bytes | None:
    """The value's bytes as ``marshal`` writes them, for the built-in types it writes (dicts, lists,
    numbers, strings, ...; no user code runs): equal bytes, an equal value, so the value need not be
    encoded again. None for any other value (a user's object, a numpy array), which is encoded each time."""
    try:
        return marshal.dumps(value)
    except (ValueError, TypeError, RecursionError):
        return None


def read(userdata: Any) -> list[tuple[Any, Any]]:
    """The userdata's (key, value) pairs, never raising (another thread may write meanwhile)."""
    try:
        data = object.__getattribute__(userdata, "_data")
    except AttributeError:
        return []
    for _ in range(3):  # a child of a Concurrence may add a key while the dict is listed
        try:
            return list(data.items())
        except RuntimeError:
            continue
    return []


class UserdataWatch:
    """The encoded values of one container's userdata, as its last event carried them."""

    __slots__ = ("_seen",)

    def __init__(self) -> None:
        self._seen: dict[str, tuple[Any, bytes | None, Any]] | None = None  # key -> (value, fingerprint, encoding)

    def snapshot(self, userdata: Any) -> dict:
        """Every key, encoded (a start's ``userdata``); kept to compare the next changes with."""
        seen = {}
        for key, value in read(userdata):
            seen[_key(key)] = (value, _fingerprint(value), encode(value))
        self._seen = seen
        return {k: v[2] for k, v in seen.items()}

    def changes(self, userdata: Any) -> dict:
        """The keys whose encoded value differs from the one last reported (or that are new), encoded."""
        seen = self._seen
        if seen is None:  # nothing reported yet in this run (observed from its middle): the baseline
            self.snapshot(userdata)
            return {}
        changed = {}
        for key, value in read(userdata):
            key = _key(key)
            before = seen.get(key)
            if before is not None and before[0] is value and type(value) in _IMMUTABLE:
                continue
            fingerprint = _fingerprint(value)
            if before is not None and fingerprint is not None and fingerprint == before[1]:
                continue
            encoded = encode(value)
            if before is None or before[2] != encoded:
                changed[key] = encoded
            seen[key] = (value, fingerprint, encoded)
        return changed

    def forget(self) -> None:
        """Nobody observes the run now starting: the next change made is compared from scratch."""
        self._seen = None
