"""Userdata: a container's key/value scope, and the Remapper through which a child sees it."""

import copy
from typing import Any, Iterable, Mapping

from . import log
from .exceptions import InvalidUserCodeError


class UserData:
    """A container's local data. A missing key logs an error and raises a bare KeyError (as SMACH)."""

    def __init__(self) -> None:
        object.__setattr__(self, "_data", {})
        # Keys written since they were last reported (fsm/core/reporting.py); a set only while a reporter listens.
        object.__setattr__(self, "_dirty", None)

    def __getattr__(self, name: str) -> Any:
        if name[0] == "_":
            raise AttributeError(name)
        try:
            return self._data[name]
        except KeyError:
            log.logerr("Userdata key '%s' not available. Available keys are: %s" % (name, list(self._data.keys())))
            raise KeyError()  # in the except block, as SMACH: the traceback shows the missing key too

    def __setattr__(self, name: str, value: Any) -> None:
        if name[0] == "_":
            object.__setattr__(self, name, value)
            return
        self._data[name] = value
        dirty = self._dirty
        if dirty is not None:
            dirty.add(name)

    def __setitem__(self, key: str, value: Any) -> None:
        """Any key, one with a leading underscore too (as SMACH's: only attribute syntax keeps those for the object)."""
        self._data[key] = value
        dirty = self._dirty
        if dirty is not None:
            dirty.add(key)

    def track_writes(self) -> None:
        """From now on, remember the keys written (for a reporter's ``userdata`` events)."""
        object.__setattr__(self, "_dirty", set())

    def take_written(self) -> dict | None:
        """The keys written since the last call, with their values; None when none was."""
        dirty = self._dirty
        if not dirty:
            return None
        data = self._data
        if len(dirty) == 1:  # a step's usual write: no comprehension (a function and a frame in 3.11)
            key = dirty.pop()
            return {key: data[key]} if key in data else {}
        written = {k: data[k] for k in dirty if k in data}
        dirty.clear()
        return written

    __getitem__ = __getattr__

    def keys(self) -> list[str]:
        return list(self._data.keys())

    def __contains__(self, key: str) -> bool:
        return key in self._data

    def update(self, other: "UserData | Mapping[str, Any]") -> None:
        """Merge another UserData (or, beyond SMACH, a plain mapping) into this one."""
        items = other._data if isinstance(other, UserData) else other
        for key, value in dict(items).items():
            self[key] = value

    def extract(self, keys: Iterable[str], remapping: Mapping[str, str]) -> "UserData":
        """A new UserData holding shallow copies of ``keys``, each under its local name (``remapping``
        maps local names to these keys), as SMACH's."""
        ud = UserData()
        reverse = {v: k for k, v in remapping.items()}
        if len(reverse) != len(remapping):
            log.logerr("SMACH userdata remapping is not one-to-one: " + str(remapping))
        for k in keys:
            ud[reverse.get(k, k)] = copy.copy(self[k])
        return ud

    def merge(self, ud: "UserData", keys: Iterable[str], remapping: Mapping[str, str]) -> None:
        """Shallow copies of ``ud``'s ``keys``, each stored under ``remapping``'s name for it, as SMACH's."""
        for k in keys:
            self[remapping.get(k, k)] = copy.copy(ud[k])

    def __str__(self) -> str:
        return str(self._data)


class Const:
    """Read-only view of an input-only value that has a ``__dict__``.

    Fixed against SMACH: setting an attribute raises (SMACH's guard never fired), and
    methods of the wrapped object can be called (SMACH wrapped them uncallable).
    """

    def __init__(self, obj: Any) -> None:
        log.logdebug("Making const '%s'" % str(obj))
        object.__setattr__(self, "_obj", obj)

    def __getattr__(self, name: str) -> Any:
        log.logdebug("Getting '%s' from const wrapper." % name)
        return get_const(getattr(self._obj, name))

    def __getitem__(self, name: Any) -> Any:
        log.logdebug("Getting '%s' from const wrapper." % name)
        return get_const(self._obj[name])

    def __setattr__(self, name: str, value: Any) -> None:
        log.logerr("Attempting to set '%s' but this member is read-only." % name)
        raise TypeError()

    def __delattr__(self, name: str) -> None:
        log.logerr("Attempting to delete '%s' but this member is read-only." % name)
        raise TypeError()

    def __repr__(self) -> str:
        return repr(self._obj)

    def __str__(self) -> str:
        return str(self._obj)


def get_const(obj: Any) -> Any:
    """Wrap objects with a ``__dict__``; callables are returned as they are so they can run."""
    if hasattr(obj, "__dict__") and not callable(obj):
        log.logdebug("Making const '%s'" % str(obj))  # and Const logs it again, as in SMACH
        return Const(obj)
    return obj


class Remapper:
    """What a child state sees: only its declared keys, under its local names."""

    __slots__ = ("_ud", "_input", "_output", "_remapping")

    def __init__(self, ud: Any, input_keys: Iterable[str] = (), output_keys: Iterable[str] = (),
                 remapping: Mapping[str, str] | None = None) -> None:
        object.__setattr__(self, "_ud", ud)
        object.__setattr__(self, "_input", frozenset(input_keys))
        object.__setattr__(self, "_output", frozenset(output_keys))
        object.__setattr__(self, "_remapping", remapping or {})

    def _remap(self, key: str) -> str:
        return self._remapping.get(key, key)

    def __getattr__(self, name: str) -> Any:
        if name[0] == "_":
            raise AttributeError(name)
        if name not in self._input:
            raise InvalidUserCodeError(
                "Reading from SMACH userdata key '%s' but the only keys that were declared as input to this state were: %s. "
                "This key needs to be declared as input to this state. " % (name, tuple(self._input)))
        if name not in self._output:
            return get_const(self._ud[self._remapping.get(name, name)])
        return self._ud[self._remapping.get(name, name)]

    def __setattr__(self, name: str, value: Any) -> None:
        if name[0] == "_":
            object.__setattr__(self, name, value)
            return
        if name not in self._output:
            log.logerr("Writing to SMACH userdata key '%s' but the only keys that were declared as output from this state were: %s."
                       % (name, tuple(self._output)))
            return
        self._ud[self._remapping.get(name, name)] = value

    __getitem__ = __getattr__
    __setitem__ = __setattr__

    def keys(self) -> list[str]:
        """The local names of the declared input keys present in the parent (fixed: SMACH mixed up the names)."""
        return [k for k in self._input if self._remap(k) in self._ud]

    def __contains__(self, key: str) -> bool:
        return key in self._input and self._remap(key) in self._ud

    def update(self, other: Any) -> None:
        self._ud.update(other)
