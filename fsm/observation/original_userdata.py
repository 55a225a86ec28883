"""A container's userdata in a machine of the original SMACH, as last reported: what changed since.

The original's ``UserData`` keeps no record of writes (fsm's tracks the keys written), so a change
is told by comparing values with those last reported: at a container's start every key is encoded
and kept; at each transition and termination each key is compared, and only the keys whose value
differs (or that are new) are encoded again and, when their encoding differs, are the change.

The comparison is what smach_ros pays per transition for its pickle, or less:

- a value of an immutable built-in type (str, int, float, ...) against the last one, by type and
  ``==`` (the very same object: nothing to compare);
- a value of built-in containers (dicts, lists, ... of built-in values: what ``marshal`` writes) by
  ``==`` against a copy of it made when it was last encoded, as ``marshal`` copies it (so a list
  changed in place is seen; no user code runs in making the copy, and the comparison is of built-in
  values unless the container came to hold a user's object since: that object's ``__eq__`` may
  then be asked once, and a comparison that raises counts as a change);
- any other value (a user's object, a numpy array) is encoded each time.

The userdata is only read, through its ``_data`` dict (read-only; reading ``ud._dirty`` or any
other missing ``_`` name of the original raises inside its ``__getattr__``), copied in one call
(``dict.copy``: no lock of the original taken, no ``__getattr__`` run, a Concurrence's child adding
a key meanwhile changes nothing midway) and compared key by key in one loop written out: it runs
for every key at every step.
"""

from __future__ import annotations

import marshal
from typing import Any

from .encoding import _key, encode

# Values compared by type and value: the same value cannot differ in place.
_ATOMS = frozenset((str, int, float, bool, type(None), bytes, complex))
_NO_COPY = object()  # a value with no built-in copy: encoded each time
_NEW = object()  # the encoding of a key not seen before: differs from any


def _copy(value: Any) -> Any:
    """A copy of ``value`` made of built-in values only (``marshal``'s: no user code runs), to compare
    the value with later; ``_NO_COPY`` for a value that holds anything else."""
    try:
        return marshal.loads(marshal.dumps(value))
    except (ValueError, TypeError, RecursionError, EOFError):
        return _NO_COPY


def _data(userdata: Any) -> dict:
    """The userdata's dict of values ({} for anything without one)."""
    try:
        return object.__getattribute__(userdata, "_data")
    except AttributeError:
        return {}


class UserdataWatch:
    """The values of one container's userdata as its last event carried them."""

    __slots__ = ("_seen", "_userdata", "_data")

    def __init__(self) -> None:
        # key -> (its string, the value or its copy to compare with, the value's encoding)
        self._seen: dict[Any, tuple[str, Any, Any]] | None = None
        self._userdata: Any = None  # the UserData last read, and its dict (set once by the original)
        self._data: dict = {}

    def _values(self, userdata: Any) -> dict:
        """A copy of the userdata's dict, made in one call (a Concurrence's child may add a key
        meanwhile); never raising."""
        if userdata is not self._userdata:
            self._userdata, self._data = userdata, _data(userdata)
        data = self._data
        try:
            return data.copy()
        except Exception:  # a mapping of a user's, or changed while copied (a key's own __eq__)
            for _ in range(3):
                try:
                    return dict(data)
                except RuntimeError:
                    continue
            return {}

    def snapshot(self, userdata: Any) -> dict:
        """Every key, encoded (a start's ``userdata``); kept to compare the next changes with."""
        seen = {}
        for key, value in self._values(userdata).items():
            seen[key] = (_key(key), _kept(value), encode(value))
        self._seen = seen
        return {name: encoded for name, _, encoded in seen.values()}

    def changes(self, userdata: Any) -> dict:
        """The keys whose value differs from the one last reported (or that are new), encoded."""
        seen = self._seen
        if seen is None:  # nothing reported yet in this run (observed from its middle): the baseline
            self.snapshot(userdata)
            return {}
        values = self._values(userdata)
        changed = {}
        for key, value in values.items():
            try:
                name, kept, encoded = seen[key]
            except KeyError:  # a new key
                name, encoded = _key(key), _NEW
            else:
                if value is kept:
                    continue
                if type(value) is type(kept):
                    try:
                        if value == kept:
                            continue
                    except Exception:  # a value holding a user's object whose comparison raises
                        pass
            new = encode(value)
            if new != encoded or type(new) is not type(encoded):  # 3.0 is not 3, nor True 1, on the page
                changed[name] = new
            seen[key] = (name, value if type(value) in _ATOMS else _copy(value), new)
        return changed

    def forget(self) -> None:
        """Nobody observes the run now starting: the next change made is compared from scratch."""
        self._seen = None


def _kept(value: Any) -> Any:
    """What ``value`` is compared with later: itself when immutable, else its built-in copy."""
    return value if type(value) in _ATOMS else _copy(value)

