"""The validator: what is wrong with an event, in words (None when it fits the schema).

Every door an event comes in through from outside (a log file, a publisher's ingest, a replay)
calls :func:`validate`; an event it refuses never reaches a ``Status``, a graph or a client. The
common case (a well-formed event) is answered by a fast test compiled from the definitions; the
words are found only for an event that does not fit.
"""

from __future__ import annotations

from typing import Any, Callable

from .events import ENVELOPE, KINDS
from .fields import Field, Type, fields_problem

_MISSING = object()
Compiled = tuple[tuple[str, "tuple | None", "Callable[[Any], bool] | None", bool], ...]


def _compile(fields: tuple[Field, ...]) -> Compiled:
    def fast(t: Type) -> Callable[[Any], bool] | None:
        if t.ok is not None or t.types is not None:
            return t.ok
        return lambda v: t.check(v) is None
    return tuple((f.name, f.type.types, fast(f.type), f.required) for f in fields)


def _fits(ev: dict, compiled: Compiled) -> bool:
    """The fast yes: every field present when required and of its type (no words when not)."""
    get = ev.get
    for name, types, ok, required in compiled:
        v = get(name, _MISSING)
        if v is _MISSING:
            if required:
                return False
        elif (types is not None and type(v) not in types) or (ok is not None and not ok(v)):
            return False
    return True


_ENVELOPE = _compile(ENVELOPE)
_KIND_FIELDS = {name: _compile(k.fields) for name, k in KINDS.items()}


def _structure_problem(ev: dict) -> str | None:
    if ev["root"]["path"] != ev["path"]:
        return "structure.root.path %r differs from the event's path %r" % (ev["root"]["path"], ev["path"])
    return None


# What each debug action needs besides the fields every debug event may have.
DEBUG_NEEDS = {"mode": ("mode",), "hold": ("state", "at", "reason", "detail"), "release": ("state", "at"),
               "forced": ("state", "outcome"), "breakpoints": ("breakpoints",)}


def _debug_problem(ev: dict) -> str | None:
    missing = [name for name in DEBUG_NEEDS[ev["action"]] if name not in ev]
    return "debug %s lacks '%s'" % (ev["action"], missing[0]) if missing else None


# Checks across fields, for the kinds that have them: None when the event is right.
_ACROSS: dict[str, Callable[[dict], "str | None"]] = {"structure": _structure_problem, "debug": _debug_problem}


def validate(ev: Any) -> str | None:
    """What is wrong with ``ev``, in words; None when it is a well-formed event of this schema."""
    if type(ev) is dict:
        kind = ev.get("kind")
        fields = _KIND_FIELDS.get(kind) if type(kind) is str else None
        if fields is not None and _fits(ev, _ENVELOPE) and _fits(ev, fields):
            across = _ACROSS.get(kind)
            if across is None or across(ev) is None:
                return None
    return _problem(ev)


def _problem(ev: Any) -> str | None:
    problem = fields_problem(ev, ENVELOPE, "event")
    if problem:
        return problem
    spec = KINDS.get(ev["kind"])
    if spec is None:
        return "unknown kind %r" % ev["kind"][:50]
    problem = fields_problem(ev, spec.fields, ev["kind"])
    if problem:
        return problem
    across = _ACROSS.get(spec.name)
    return across(ev) if across is not None else None


