"""JSON-safe encoding of user values and fast serialisation of events. Never pickle."""

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
_MAX_DEPTH = 16
_REPR_LEN = 200


def _short_repr(value: Any) -> str:
    try:
        text = repr(value)
    except Exception as exc:  # a user's __repr__ may raise
        text = "<unrepresentable %s: %s>" % (type(value).__name__, type(exc).__name__)
    return text if len(text) <= _REPR_LEN else text[:_REPR_LEN] + "..."


def _enc(value: Any, depth: int) -> Any:
    if value is None or value is True or value is False or type(value) is str:
        return value
    if type(value) is int:
        return value if -(2 ** 63) <= value < 2 ** 64 else str(value)
    if type(value) is float:
        if math.isfinite(value):
            return value
        return "NaN" if value != value else ("Infinity" if value > 0 else "-Infinity")
    if depth >= _MAX_DEPTH:
        return {"$repr": _short_repr(value)}
    if isinstance(value, enum.Enum):
        return "%s.%s" % (type(value).__name__, value.name)
    if isinstance(value, (list, tuple, set, frozenset)):
        return [_enc(v, depth + 1) for v in value]
    if isinstance(value, dict):
        return {k if type(k) is str else str(k): _enc(v, depth + 1) for k, v in value.items()}
    if isinstance(value, (str, int, float)):  # subclasses such as bool-likes or IntEnum handled above
        return _enc(type(value).__mro__[-2](value), depth)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _enc(getattr(value, f.name, None), depth + 1) for f in dataclasses.fields(value)}
    module = type(value).__module__
    if module == "numpy":
        if hasattr(value, "tolist"):
            return _enc(value.tolist(), depth)
    inner = getattr(value, "_obj", None)  # fsm.core.user_data.Const
    if inner is not None and type(value).__name__ == "Const":
        return _enc(inner, depth)
    return {"$repr": _short_repr(value)}


def encode(value: Any, cap: int | None = DEFAULT_CAP) -> Any:
    """A JSON-safe form of ``value``; larger than ``cap`` bytes once serialised -> a marker."""
    out = _enc(value, 0)
    if cap is not None and isinstance(out, (list, dict, str)):
        size = len(out) if isinstance(out, str) else len(dumps(out))
        if size > cap:
            return {"$truncated": True, "size": size, "repr": _short_repr(value)}
    return out


def encode_userdata(data: dict, cap: int | None = DEFAULT_CAP) -> dict:
    return {str(k): encode(v, cap) for k, v in data.items()}


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
