"""The short repr of a value, as the encoder's markers show it: ``repr`` cut after 200 characters.

Made piece by piece, not by cutting ``repr(value)``: the plain containers (list, tuple, set,
frozenset, dict) and dataclasses are written here, so that one which is big only when written out
(shared references, deep nesting, millions of items, an int of a million digits, which ``repr``
refuses) costs no more than the cut. A user's own ``__repr__`` is called as it is.
"""

from __future__ import annotations

import dataclasses
from typing import Any

REPR_LEN = 200
_MAX_INT_BITS = 14_000  # at most 4,215 decimal digits: under Python's limit on int to str (4,300)
CONTAINERS = (list, tuple, set, frozenset, dict)  # what is written here, item by item


def int_text(value: int) -> str | None:
    """``str(value)`` of an int, or None when it has too many digits to be written."""
    return None if value.bit_length() > _MAX_INT_BITS else str(value)


class _Full(Exception):
    """The short repr has its length."""


def short_repr(value: Any) -> str:
    """``repr(value)`` cut after ``REPR_LEN`` characters (then "..."), made piece by piece; never raises."""
    pieces: list[str] = []
    left = [REPR_LEN + 1]

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
            put(int_text(v) or "<int of %d bits>" % v.bit_length())
            return
        if not isinstance(v, CONTAINERS) and not _plain_dataclass(v):
            try:
                put(repr(v))
            except _Full:
                raise
            except Exception as exc:  # a user's __repr__ may raise
                put("<unrepresentable %s: %s>" % (type(v).__name__, type(exc).__name__))
            return
        if id(v) in inside:
            put(cycle(v))
            return
        inside = inside | {id(v)}
        if isinstance(v, dict):
            items = list(_first(v.items()))
            opening, closing = "{", "}"
        elif isinstance(v, CONTAINERS):
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
        return "".join(pieces)[:REPR_LEN] + "..."
    except Exception as exc:  # a dataclass's field that raises, a dict changed by another thread meanwhile
        return "<unrepresentable %s: %s>" % (type(value).__name__, type(exc).__name__)
    return "".join(pieces)


def _first(items: Any) -> Any:
    """The first items of a container, as many as a short repr can show."""
    for i, item in enumerate(items):
        if i > REPR_LEN // 2:
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
    """A dataclass instance whose repr is the generated one (which ``short_repr`` writes itself)."""
    return (dataclasses.is_dataclass(value) and not isinstance(value, type)
            and hasattr(type(value).__repr__, "__wrapped__"))


def cycle(value: Any) -> str:
    """What repr writes for a container met again inside itself."""
    if isinstance(value, list):
        return "[...]"
    if isinstance(value, dict):
        return "{...}"
    return "%s(...)" % type(value).__name__
