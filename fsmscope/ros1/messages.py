"""ROS 1 message types: their md5sums and definitions as genmsg computes them, and a message's
bytes to and from a plain dict, through the kept library rosbags (ROS Noetic's types, plus
smach_msgs' three from fsmscope/interop/smach_msgs.py).

In a plain dict nested messages are dicts, arrays lists, ``uint8[]`` bytes, a time or a duration
``{"sec", "nanosec"}``. A ``string`` is a str where its bytes are UTF-8 and the bytes where they
are not: the wire form of ``string`` and ``uint8[]`` is the same, and a ROS 1 robot before
Noetic put a raw pickle in SmachContainerStatus's ``local_data``. So a type is read and written
through a twin whose ``string`` fields are ``uint8[]`` (rosbags would fail on bytes that are no
UTF-8), and the strings are decoded here.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import numpy as np
from rosbags.interfaces import Nodetype
from rosbags.typesys import Stores, TypesysError, get_typestore
from rosbags.typesys.store import Typestore

from fsmscope.interop import smach_msgs

from .errors import Ros1Error

_TIME_TYPES = ("builtin_interfaces/msg/Time", "builtin_interfaces/msg/Duration")
_DTYPES = {"bool": np.bool_, "byte": np.int8, "char": np.uint8}  # the others are numpy's own names
_BYTES = (Nodetype.BASE, ("uint8", 0))
_STRING_AS_BYTES = (Nodetype.SEQUENCE, (_BYTES, 0))
_PLACEHOLDER = "structure_needs_at_least_one_member"  # rosbags' field of an empty message, never on ROS 1's wire


@functools.cache
def _store() -> Typestore:
    return smach_msgs.typestore(ros2=False)


class MessageType:
    """One ROS 1 type (``name``: ``pkg/Type``): its ``md5sum`` and ``definition`` (the text of its
    connection header), ``decode`` and ``encode`` between its bytes and a plain dict."""

    def __init__(self, name: str) -> None:
        package, _, short = name.partition("/")
        if not package or not short or "/" in short:
            raise Ros1Error("%r is not a ROS 1 type name (package/Type)" % name)
        self.name = name
        self._typename = "%s/msg/%s" % (package, short)
        store = _store()
        if self._typename not in store.fielddefs:
            raise Ros1Error("%s is a type this client does not know (it knows ROS Noetic's and smach_msgs')"
                            % name)
        self.definition, self.md5sum = store.generate_msgdef(self._typename, ros_version=1)
        self._fields = store.fielddefs
        self._twin = _twin(self._typename)
        self.has_header = any(field == ("header", (Nodetype.NAME, "std_msgs/msg/Header"))
                              for field in self._fields[self._typename][1])

    def decode(self, raw: bytes) -> dict[str, Any]:
        """The message of ``raw`` as a plain dict; a Ros1Error saying why if it does not decode."""
        try:
            message = self._twin.deserialize_ros1(raw, self._typename)
        except Exception as error:  # rosbags' generated code raises struct.error, IndexError, ValueError...
            reason = str(error) or type(error).__name__
            raise Ros1Error("%d bytes that are no %s: %s" % (len(raw), self.name, reason)) from error
        return self._plain(message, self._typename)

    def encode(self, fields: dict[str, Any]) -> bytes:
        """The bytes of the message ``fields`` gives; a field it leaves out is zero, empty or a
        default message. A Ros1Error says which field does not fit."""
        message = self._built(fields, self._typename, self.name)
        try:
            return bytes(self._twin.serialize_ros1(message, self._typename))
        except Exception as error:  # a value numpy took but the wire cannot hold (a negative length...)
            raise Ros1Error("fields that make no %s: %s" % (self.name, error)) from error

    def _plain(self, message: Any, typename: str) -> dict[str, Any]:
        plain = {}
        for name, (kind, spec) in self._fields[typename][1]:
            if name == _PLACEHOLDER:
                continue
            value = getattr(message, name)
            if kind == Nodetype.BASE:
                plain[name] = _text(value) if spec[0] == "string" else value
            elif kind == Nodetype.NAME:
                plain[name] = self._plain(value, spec)
            else:
                (item_kind, item_spec), _ = spec
                if item_kind == Nodetype.NAME:
                    plain[name] = [self._plain(item, item_spec) for item in value]
                elif item_spec[0] in ("uint8", "char"):
                    plain[name] = bytes(value)
                elif item_spec[0] == "string":
                    plain[name] = list(value)
                else:
                    plain[name] = value.tolist()
        return plain

    def _built(self, fields: Any, typename: str, where: str) -> Any:
        if typename in _TIME_TYPES and isinstance(fields, (int, float)) and math.isfinite(fields):
            sec, nanosec = divmod(round(fields * 1e9), 1_000_000_000)
            fields = {"sec": sec, "nanosec": nanosec}
        if not isinstance(fields, dict):
            raise Ros1Error("%s: a message is given as a dict, not %s" % (where, type(fields).__name__))
        spec_of = dict(self._fields[typename][1])
        unknown = sorted(set(fields) - set(spec_of) | set(fields) & {_PLACEHOLDER})
        if unknown:
            raise Ros1Error("%s has no field %s" % (where, ", ".join(unknown)))
        values = {name: self._value(fields.get(name), kind, spec, "%s.%s" % (where, name))
                  for name, (kind, spec) in spec_of.items()}
        return self._twin.types[typename](**values)

    def _value(self, value: Any, kind: Nodetype, spec: Any, where: str) -> Any:
        try:
            if kind == Nodetype.NAME:
                return self._built({} if value is None else value, spec, where)
            if kind == Nodetype.BASE:
                return _base(value, spec[0])
            (item_kind, item_spec), count = spec
            items = [] if value is None else value
            as_bytes = isinstance(items, (bytes, bytearray)) and item_spec[0] in ("uint8", "char")
            if not as_bytes and not isinstance(items, (list, tuple)):
                raise TypeError("an array is a list, not %s" % type(items).__name__)
            if item_kind == Nodetype.NAME:
                items = items or [{}] * count
                built = [self._built(item, item_spec, "%s[%d]" % (where, i)) for i, item in enumerate(items)]
            elif item_spec[0] == "string":
                built = [_base(item, "string_item") for item in (items or [""] * count)]
            else:
                dtype = _DTYPES.get(item_spec[0], item_spec[0])
                built = np.frombuffer(items, dtype=np.uint8) if as_bytes else np.array(items, dtype=dtype)
                built = built if len(built) or not count else np.zeros(count, dtype=dtype)
            if kind == Nodetype.ARRAY and len(built) != count:
                raise Ros1Error("%s holds %d items, not %d" % (where, count, len(built)))
            return built
        except (TypeError, ValueError, OverflowError) as error:
            raise Ros1Error("%s: %s" % (where, error)) from error


def _base(value: Any, base: str) -> Any:
    if base in ("string", "string_item"):
        value = "" if value is None else value
        if not isinstance(value, (str, bytes)):
            raise TypeError("a string is a str (or bytes), not %s" % type(value).__name__)
        if base == "string_item":
            if isinstance(value, bytes):
                raise TypeError("an item of string[] is a str")
            return value
        return np.frombuffer(value.encode() if isinstance(value, str) else value, dtype=np.uint8)
    if base == "bool":
        return bool(value)
    if base in ("float32", "float64"):
        return float(value or 0)
    if value is not None and not isinstance(value, int):
        raise TypeError("an integer, not %r" % (value,))
    return value or 0


def _text(raw: Any) -> str | bytes:
    data = bytes(raw)
    try:
        return data.decode()
    except UnicodeDecodeError:
        return data


@functools.cache
def _twin(typename: str) -> Typestore:
    """A typestore of ``typename`` and the types it holds, each ``string`` field made ``uint8[]``."""
    store = _store()
    types: dict[str, Any] = {}
    pending = [typename]
    while pending:
        name = pending.pop()
        if name in types or name in _TIME_TYPES:
            continue
        consts, fields = store.fielddefs[name]
        types[name] = (consts, [(field, _STRING_AS_BYTES if spec == (Nodetype.BASE, ("string", 0)) else spec)
                                for field, spec in fields])
        for _, (kind, spec) in fields:
            if kind == Nodetype.NAME:
                pending.append(spec)
            elif kind in (Nodetype.SEQUENCE, Nodetype.ARRAY) and spec[0][0] == Nodetype.NAME:
                pending.append(spec[0][1])
    twin = get_typestore(Stores.EMPTY)
    try:
        twin.register(types)
    except TypesysError as error:
        raise Ros1Error("%s cannot be read: %s" % (typename, error)) from error
    return twin


@functools.cache
def message_type(name: str) -> MessageType:
    """The ROS 1 type ``name`` (``pkg/Type``); a Ros1Error if it is not one this client knows."""
    return MessageType(name)
