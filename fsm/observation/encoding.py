"""JSON-safe encoding of user values and fast serialisation of events. Never pickle.

Encoding is bounded by what it makes, not by what it is given: a value that is small in memory
can be huge when expanded (a list of ten references to a list of ten references to ..., 368
bytes as a pickle, 10^14 items as JSON; a cycle; an int of a million digits). The encoder
walks each container once per depth (a shared one met again reuses its encoding, a cycle is
cut with a marker), counts a lower bound of the bytes it has made, and stops at the cap; a
marker's text is made piece by piece up to its length (short_repr.py). Encoding never raises:
what cannot be encoded becomes a marker, so observing a machine never changes what it does.
"""

import dataclasses
import enum
import json
import math
from typing import Any

from .short_repr import CONTAINERS, cycle, int_text, short_repr

try:
    import orjson
except ImportError:  # the runtime must work with the standard library alone
    orjson = None

DEFAULT_CAP = 8192
MAX_UNCAPPED = 16 << 20  # bytes an encoding without a cap may still take
_MAX_DEPTH = 16


class _Over(Exception):
    """The encoding has grown past its budget."""


def _marker(value: Any) -> dict:
    return {"$repr": short_repr(value)}


class _Walk:
    """One value's encoding: the bytes it may still take (counted low: a number as one character,
    a string as its length), and what it has made of each container at each depth."""

    __slots__ = ("room", "made", "open")

    def __init__(self, budget: int) -> None:
        self.room = budget
        self.made: dict[tuple[int, int], tuple[Any, Any, int]] = {}  # (id, depth) -> (value, encoded, bytes)
        self.open: set[int] = set()  # ids of the containers being encoded: met again inside, a cycle

    def take(self, size: int) -> None:
        self.room -= size
        if self.room < 0:
            raise _Over

    def enc(self, value: Any, depth: int) -> Any:
        """The encoding of ``value``; the bytes it takes are counted (a caller checks the room left)."""
        t = type(value)
        if t is str:
            self.room -= len(value) + 2
            return value
        if value is None or value is True or value is False:
            self.room -= 4
            return value
        if t is int:
            if -(2 ** 63) <= value < 2 ** 64:
                self.room -= 1
                return value
            text = int_text(value)
            if text is None:
                return self.opaque({"$repr": "<int of %d bits>" % value.bit_length()})
            self.room -= len(text) + 2
            return text
        if t is float:
            self.room -= 1
            if math.isfinite(value):
                return value
            return "NaN" if value != value else ("Infinity" if value > 0 else "-Infinity")
        if self.room < 0:
            raise _Over
        if depth >= _MAX_DEPTH:
            return self.opaque(_marker(value))
        if t is list or t is dict or t is tuple:
            return self.container(value, depth)
        if isinstance(value, enum.Enum):
            return self.enc("%s.%s" % (type(value).__name__, value.name), depth)
        if isinstance(value, CONTAINERS) or (dataclasses.is_dataclass(value) and not isinstance(value, type)):
            return self.container(value, depth)
        if isinstance(value, (str, int, float)):  # subclasses such as bool-likes or IntEnum handled above
            return self.enc(type(value).__mro__[-2](value), depth)
        if type(value).__module__ == "numpy" and hasattr(value, "tolist"):
            items = getattr(value, "size", 1)
            if items > self.room:  # each item takes a byte at least: too big before it is listed
                self.take(items)
            return self.enc(value.tolist(), depth)
        inner = getattr(value, "_obj", None)  # fsm.core.user_data.Const
        if inner is not None and type(value).__name__ == "Const":
            return self.enc(inner, depth)
        return self.opaque(_marker(value))

    def opaque(self, marker: dict) -> dict:
        self.room -= len(marker["$repr"]) + 12
        return marker

    def container(self, value: Any, depth: int) -> Any:
        key = (id(value), depth)
        done = self.made.get(key)
        if done is not None:  # a shared reference: its encoding again, its bytes counted again
            self.take(done[2])
            return done[1]
        if id(value) in self.open:
            return self.opaque({"$repr": cycle(value)})
        self.open.add(id(value))
        before = self.room
        fields = None if isinstance(value, CONTAINERS) else dataclasses.fields(value)
        self.take(1 + max(len(value if fields is None else fields), 1))  # brackets and commas
        enc = self.enc
        inner = depth + 1
        if isinstance(value, dict):
            out: Any = {}
            for k, v in value.items():
                k = _key(k)
                self.room -= len(k) + 3
                out[k] = enc(v, inner)
                if self.room < 0:
                    raise _Over
        elif isinstance(value, CONTAINERS):
            out = []
            for v in value:
                out.append(enc(v, inner))
                if self.room < 0:
                    raise _Over
        else:
            out = {}
            for f in fields:
                self.room -= len(f.name) + 3
                out[f.name] = enc(getattr(value, f.name, None), inner)
                if self.room < 0:
                    raise _Over
        self.open.discard(id(value))
        self.made[key] = (value, out, before - self.room)  # the value held: its id is not reused meanwhile
        return out


def _key(key: Any) -> str:
    """A dict key as a string (JSON's keys are)."""
    if type(key) is str:
        return key
    if type(key) is int:
        return int_text(key) or "<int of %d bits>" % key.bit_length()
    if isinstance(key, (tuple, frozenset)):
        return short_repr(key)
    try:
        return str(key)
    except Exception as exc:  # a user's __str__ may raise
        return "<unrepresentable %s: %s>" % (type(key).__name__, type(exc).__name__)


_SHORT = 32  # items of a list of plain numbers encoded without a walk: 32 x 24 characters fit any cap met


def _plain_numbers(value: list | tuple) -> bool:
    """A short list of finite numbers (a pose, a joint vector): its encoding is a copy of it."""
    if len(value) > _SHORT:
        return False
    for x in value:
        t = type(x)
        if t is float:
            if x - x != 0:  # inf or nan
                return False
        elif t is not int or not -(2 ** 63) <= x < 2 ** 64:
            return False
    return True


def encode(value: Any, cap: int | None = DEFAULT_CAP) -> Any:
    """A JSON-safe form of ``value``; larger than ``cap`` bytes once serialised -> a marker."""
    t = type(value)
    if (value is None or t is bool or (t is int and -(2 ** 63) <= value < 2 ** 64)
            or (t is float and math.isfinite(value)) or (t is str and (cap is None or len(value) <= cap))):
        return value
    if (t is list or t is tuple) and (cap is None or cap >= _SHORT * 24) and _plain_numbers(value):
        return list(value)
    walk = _Walk(MAX_UNCAPPED if cap is None else cap)
    try:
        out = walk.enc(value, 0)
        if walk.room < 0:
            raise _Over
    except _Over:
        size = (MAX_UNCAPPED if cap is None else cap) - walk.room
        return {"$truncated": True, "size": size, "repr": short_repr(value)}
    except Exception as exc:  # a user's value may raise anywhere (a property, __eq__, tolist)
        return {"$repr": "<unencodable %s: %s>" % (type(value).__name__, type(exc).__name__)}
    if cap is not None and isinstance(out, (list, dict, str)):  # counted low: the real size decides
        size = len(out) if isinstance(out, str) else len(dumps(out))
        if size > cap:
            return {"$truncated": True, "size": size, "repr": short_repr(value)}
    return out


_SAFE = frozenset((str, int, float, bool, type(None)))  # types whose common values encode as they are


def encode_userdata(data: dict, cap: int | None = DEFAULT_CAP) -> dict:
    """``encode`` of each value under ``_key`` of its key: what a step wrote, on every observed step,
    so the common case (a string key, a plain number, flag or short text) is tested here before a call."""
    out = {}
    for key, value in data.items():
        t = type(value)
        if t in _SAFE and (t is not int or -(2 ** 63) <= value < 2 ** 64) and (t is not float or math.isfinite(value)) \
                and (t is not str or cap is None or len(value) <= cap):
            out[key if type(key) is str else _key(key)] = value
        else:
            out[key if type(key) is str else _key(key)] = encode(value, cap)
    return out


def encode_written(written: dict, cap: int = DEFAULT_CAP) -> dict:
    """``encode_userdata`` of a dict made for the purpose (``UserData.take_written``'s, which nobody else
    holds): itself when every key is a string and every value is already as it would be encoded (a
    step's usual write: a count, a flag, a short text), without a copy; else the encoding."""
    for key, value in written.items():
        t = type(value)
        if type(key) is not str or not (
                t is int and -(2 ** 63) <= value < 2 ** 64 or t is str and len(value) <= cap or value is None
                or t is bool or t is float and math.isfinite(value)):
            return encode_userdata(written, cap)
    return written


if orjson is not None:
    _OPT = orjson.OPT_NON_STR_KEYS

    def dumps(obj: Any, _dumps: Any = orjson.dumps) -> bytes:
        """Serialise an already JSON-safe object (events are built from encoded values, whose keys are
        strings: allowing others costs orjson 40 % more on every event, so it is done only when asked)."""
        try:
            return _dumps(obj)
        except TypeError:
            return _dumps(obj, option=_OPT)

    def dumps_all(objs: Any, _dumps: Any = orjson.dumps) -> list[bytes]:
        """``dumps`` of each object, in one call for a batch of events: orjson's loop, not Python's."""
        try:
            return list(map(_dumps, objs))
        except TypeError:
            return [dumps(obj) for obj in objs]

    loads = orjson.loads
else:
    def dumps(obj: Any) -> bytes:
        return json.dumps(obj, separators=(",", ":"), ensure_ascii=False).encode()

    def dumps_all(objs: Any) -> list[bytes]:
        return list(map(dumps, objs))

    loads = json.loads


_last_encoded: tuple[Any, bytes] = (None, b"")


def encoded(event: dict) -> bytes:
    """``dumps(event)``, done once for all the observers of an event that keep or send it as bytes
    (the dashboard's hub, the recorder, a Zenoh robot): a reporter hands the same dict to its
    observers one after another, and the second finds the first's bytes here. One slot for the
    process, matched by identity and holding the dict (so its id is never reused meanwhile): a
    machine in another thread may take the slot in between, and then the bytes are made again,
    never wrong. Observers do not change the events they are given."""
    global _last_encoded
    last = _last_encoded
    if last[0] is event:
        return last[1]
    data = dumps(event)
    _last_encoded = (event, data)
    return data
