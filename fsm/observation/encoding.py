"""JSON-safe encoding of user values and fast serialisation of events. Never pickle.

Encoding is bounded by what it makes, not by what it is given: a value that is small in memory
can be huge when expanded (a list of ten references to a list of ten references to ..., 368
bytes as a pickle, 10^14 items as JSON; a cycle; an int of a million digits). The encoder
walks each container once per depth (a shared one met again reuses its encoding, a cycle is
cut with a marker), counts a lower bound of the bytes it has made, and stops at the cap; the
short repr of a marker is made piece by piece up to its length. Encoding never raises: what
cannot be encoded becomes a marker, so observing a machine never changes what it does.
"""

import dataclasses
import enum
import json
import math
from typing import Any

try:
    import orjson
except ImportError:  # the runtime must work with the standard library alone
    orjson = None

DEFAULT_CAP = 8192
MAX_UNCAPPED = 16 << 20  # bytes an encoding without a cap may still take
_MAX_DEPTH = 16
_REPR_LEN = 200
_MAX_INT_BITS = 14_000  # at most 4,215 decimal digits: under Python's limit on int to str (4,300)
_CONTAINERS = (list, tuple, set, frozenset, dict)


class _Over(Exception):
    """The encoding has grown past its budget."""


def _int_text(value: int) -> str | None:
    """``str(value)`` of an int, or None when it has too many digits to be written."""
    return None if value.bit_length() > _MAX_INT_BITS else str(value)


def _marker(value: Any) -> dict:
    return {"$repr": _short_repr(value)}


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
            text = _int_text(value)
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
        if isinstance(value, _CONTAINERS) or (dataclasses.is_dataclass(value) and not isinstance(value, type)):
            return self.container(value, depth)
        if isinstance(value, (str, int, float)):  # subclasses such as bool-likes or IntEnum handled above
            return self.enc(type(value).__mro__[-2](value), depth)
        if type(value).__module__ == "numpy" and hasattr(value, "tolist"):
            if getattr(value, "size", 1) > self.room:  # each item takes a byte at least: too big before it is listed
                raise _Over
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
            return self.opaque({"$repr": _cycle(value)})
        self.open.add(id(value))
        before = self.room
        fields = None if isinstance(value, _CONTAINERS) else dataclasses.fields(value)
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
        elif isinstance(value, _CONTAINERS):
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
        return _int_text(key) or "<int of %d bits>" % key.bit_length()
    if isinstance(key, (tuple, frozenset)):
        return _short_repr(key)
    try:
        return str(key)
    except Exception as exc:  # a user's __str__ may raise
        return "<unrepresentable %s: %s>" % (type(key).__name__, type(exc).__name__)


def encode(value: Any, cap: int | None = DEFAULT_CAP) -> Any:
    """A JSON-safe form of ``value``; larger than ``cap`` bytes once serialised -> a marker."""
    t = type(value)
    if (value is None or t is bool or (t is int and -(2 ** 63) <= value < 2 ** 64)
            or (t is float and math.isfinite(value)) or (t is str and (cap is None or len(value) <= cap))):
        return value
    walk = _Walk(MAX_UNCAPPED if cap is None else cap)
    try:
        out = walk.enc(value, 0)
        if walk.room < 0:
            raise _Over
    except _Over:
        size = (MAX_UNCAPPED if cap is None else cap) - walk.room
        return {"$truncated": True, "size": size, "repr": _short_repr(value)}
    except Exception as exc:  # a user's value may raise anywhere (a property, __eq__, tolist)
        return {"$repr": "<unencodable %s: %s>" % (type(value).__name__, type(exc).__name__)}
    if cap is not None and isinstance(out, (list, dict, str)):  # counted low: the real size decides
        size = len(out) if isinstance(out, str) else len(dumps(out))
        if size > cap:
            return {"$truncated": True, "size": size, "repr": _short_repr(value)}
    return out


def encode_userdata(data: dict, cap: int | None = DEFAULT_CAP) -> dict:
    return {_key(k): encode(v, cap) for k, v in data.items()}


class _Full(Exception):
    """The short repr has its length."""


def _short_repr(value: Any) -> str:
    """``repr(value)`` cut after ``_REPR_LEN`` characters, made piece by piece: the plain containers
    and dataclasses are written here, so that one which is big only when expanded costs no more
    than the cut (a user's own ``__repr__`` is called as it is)."""
    pieces: list[str] = []
    left = [_REPR_LEN + 1]

    def put(text: str) -> None:
        pieces.append(text[:left[0]])
        left[0] -= len(text)
        if left[0] <= 0:
            raise _Full

    def write(v: Any, inside: set[int]) -> None:
        t = type(v)
        if t is str or t is bytes:
            put(repr(v[:left[0]]) if len(v) > left[0] else repr(v))
            return
        if t is int:
            put(_int_text(v) or "<int of %d bits>" % v.bit_length())
            return
        if not isinstance(v, _CONTAINERS) and not _plain_dataclass(v):
            try:
                put(repr(v))
            except _Full:
                raise
            except Exception as exc:  # a user's __repr__ may raise
                put("<unrepresentable %s: %s>" % (type(v).__name__, type(exc).__name__))
            return
        if id(v) in inside:
            put(_cycle(v))
            return
        inside = inside | {id(v)}
        if isinstance(v, dict):
            items = list(_first(v.items()))
            opening, closing = "{", "}"
        elif isinstance(v, _CONTAINERS):
            items = [(None, x) for x in _first(v)]
            opening, closing = _brackets(v)
        else:
            items = [(f.name, getattr(v, f.name, None)) for f in dataclasses.fields(v) if f.repr]
            opening, closing = type(v).__qualname__ + "(", ")"
        put(opening)
        for i, (k, x) in enumerate(items):
            if i:
                put(", ")
            if isinstance(v, dict):
                write(k, inside)
                put(": ")
            elif k is not None:
                put(k + "=")
            write(x, inside)
        put(closing)

    try:
        write(value, set())
    except _Full:
        return "".join(pieces)[:_REPR_LEN] + "..."
    return "".join(pieces)


def _first(items: Any) -> Any:
    """The first items of a container, as many as a short repr can show."""
    for i, item in enumerate(items):
        if i > _REPR_LEN // 2:
            return
        yield item


def _brackets(value: Any) -> tuple[str, str]:
    """How repr opens and closes a list, tuple, set or frozenset."""
    if isinstance(value, list):
        return "[", "]"
    if isinstance(value, tuple):
        return "(", ",)" if len(value) == 1 else ")"
    name = "set" if isinstance(value, set) else "frozenset"
    if not value:
        return name + "(", ")"
    return ("{", "}") if name == "set" else ("frozenset({", "})")


def _plain_dataclass(value: Any) -> bool:
    """A dataclass instance whose repr is the generated one (which ``_short_repr`` writes itself)."""
    return (dataclasses.is_dataclass(value) and not isinstance(value, type)
            and hasattr(type(value).__repr__, "__wrapped__"))


def _cycle(value: Any) -> str:
    """What repr writes for a container met again inside itself."""
    if isinstance(value, list):
        return "[...]"
    if isinstance(value, dict):
        return "{...}"
    return "%s(...)" % type(value).__name__


if orjson is not None:
    _OPT = orjson.OPT_NON_STR_KEYS

    def dumps(obj: Any) -> bytes:
        """Serialise an already JSON-safe object (events are built from encoded values)."""
        return orjson.dumps(obj, option=_OPT)

    loads = orjson.loads
else:
    def dumps(obj: Any) -> bytes:
        return json.dumps(obj, separators=(",", ":"), ensure_ascii=False).encode()

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
