"""The schema's vocabulary: limits, a field's ``Type`` (its name in the docs, the check that says in
words what is wrong, a fast test), ``Field``, ``Kind``, and the types every shape is made of."""

from __future__ import annotations

import keyword
import math
from dataclasses import dataclass
from typing import Any, Callable

from ..names import MAX_NAME, is_valid as is_name

VERSION = 1
MAX_SEQ = 2 ** 53 - 1          # the browser's largest exact integer
MAX_PATH = 4096                # a container or state path
MAX_STRUCTURE_DEPTH = 64       # container levels; JSON encoders refuse much deeper nesting
MAX_STRUCTURE_NODES = 200_000
MAX_DOC = 500                  # characters of a structure node's class docstring
MAX_VALUE_DEPTH = 32           # nesting of a JSON value (userdata is cut at 16 levels when encoded)


Problem = Callable[[Any], "str | None"]  # a type check: None when the value fits, else what is wrong


@dataclass(frozen=True)
class Type:
    """A field's type: its name in the docs, the check that says what is wrong (or None), and a
    fast test for the common case: the exact Python types allowed (None: any), then ``ok(value)``.
    ``js``: its type in the browser's JSDoc typedefs; ``null``: null is allowed; ``shape``: the
    fields of an object of a shape of its own (its typedef is named ``js``)."""

    name: str
    check: Problem
    types: tuple | None = None
    ok: Callable[[Any], bool] | None = None
    js: str = "*"
    null: bool = False
    shape: tuple[Field, ...] | None = None


@dataclass(frozen=True)
class Field:
    name: str
    type: Type
    required: bool = True
    doc: str = ""


@dataclass(frozen=True)
class Kind:
    name: str
    doc: str
    fields: tuple[Field, ...]


def _what(value: Any) -> str:
    return {type(None): "null", bool: "a boolean", int: "an integer", float: "a number", str: "a string",
            list: "a list", dict: "an object"}.get(type(value), type(value).__name__)


_JS = {str: "string", bool: "boolean", int: "number", float: "number", list: "Array<*>", dict: "Object<string, *>"}


def simple(name: str, types: tuple, ok: Callable[[Any], bool] | None = None) -> Type:
    """A type that is right when the value is of one of ``types`` and passes ``ok``."""
    def check(v: Any) -> str | None:
        return None if type(v) in types and (ok is None or ok(v)) else "must be %s, not %s" % (name, _what(v))
    return Type(name, check, types, ok, js="|".join(dict.fromkeys(_JS[t] for t in types)))


def nullable(t: Type) -> Type:
    name = t.name + " or null"

    def check(v: Any) -> str | None:
        problem = None if v is None else t.check(v)
        return problem and problem.replace("must be " + t.name, "must be " + name, 1)

    ok = None if t.ok is None else (lambda v, inner=t.ok: v is None or inner(v))
    return Type(name, check, None if t.types is None else t.types + (type(None),), ok, js="(%s|null)" % t.js,
                null=True, shape=t.shape)


STR = simple("a string", (str,))
BOOL = simple("a boolean", (bool,))
NUMBER = simple("a finite number", (float, int), lambda v: type(v) is int or math.isfinite(v))
SEQ = simple("an integer from 0 to 2^53-1", (int,), lambda v: 0 <= v <= MAX_SEQ)
NAME = simple("a name of 1 to %d characters (no / * $ ? #, control character or outer space)" % MAX_NAME,
              (str,), is_name)
PATH = simple("a string of 1 to %d characters" % MAX_PATH, (str,), lambda v: 0 < len(v) <= MAX_PATH)
OPT_STR = nullable(STR)
OPT_NUMBER = nullable(NUMBER)


def one_of(*values: str) -> Type:
    shown = ", ".join("'%s'" % v for v in values)
    t = simple("one of " + shown, (str,), lambda v: v in values)
    return Type(t.name, t.check, t.types, t.ok, js="(%s)" % "|".join('"%s"' % v for v in values))


def list_of(item: Type, name: str, ok: Callable[[Any], bool] | None = None) -> Type:
    def check(v: Any) -> str | None:
        if type(v) is not list:
            return "must be %s, not %s" % (name, _what(v))
        for i, x in enumerate(v):
            problem = item.check(x)
            if problem:
                return _join("[%d]" % i, problem)
        return None
    return Type(name, check, (list,), ok or (lambda v: check(v) is None), js="Array<%s>" % item.js)


def object_of(value: Type, name: str) -> Type:
    def check(v: Any) -> str | None:
        if type(v) is not dict:
            return "must be %s, not %s" % (name, _what(v))
        for k, x in v.items():
            problem = value.check(x)
            if problem:
                return _join("[%r]" % (k,), problem)
        return None
    return Type(name, check, (dict,), lambda v: check(v) is None, js="Object<string, %s>" % value.js)


def _all_str(v: list) -> bool:
    for x in v:
        if type(x) is not str:
            return False
    return True


def _json_depth_problem(v: Any, depth: int) -> str | None:
    if depth > MAX_VALUE_DEPTH:
        return "is nested deeper than %d levels" % MAX_VALUE_DEPTH
    t = type(v)
    if t is dict:
        for x in v.values():
            if type(x) in (dict, list):
                problem = _json_depth_problem(x, depth + 1)
                if problem:
                    return problem
    elif t is list:
        for x in v:
            if type(x) in (dict, list):
                problem = _json_depth_problem(x, depth + 1)
                if problem:
                    return problem
    elif t is float and not math.isfinite(v):
        return "holds a non-finite number"
    return None


JSON = Type("any JSON value", lambda v: _json_depth_problem(v, 0), None, lambda v: _json_depth_problem(v, 0) is None)
OBJECT = Type("an object", lambda v: ("must be an object, not %s" % _what(v)) if type(v) is not dict
              else _json_depth_problem(v, 0), (dict,), lambda v: _json_depth_problem(v, 0) is None,
              js="Object<string, *>")
LIST_STR = list_of(STR, "a list of strings", _all_str)
MAP_STR = object_of(STR, "an object of strings")
MAP_OPT_STR = object_of(OPT_STR, "an object of strings or nulls")
MAP_NUMBER = object_of(NUMBER, "an object of finite numbers")


def _sized(t: Type, n: int) -> Type:
    """``t`` (a list type) holding exactly ``n`` items."""
    def check(v: Any) -> str | None:
        return t.check(v) or (None if len(v) == n else "must hold %d items, not %d" % (n, len(v)))
    return Type(t.name, check, t.types, lambda v: len(v) == n and t.ok(v), js=t.js)


BODY_POSE = _sized(list_of(NUMBER, "a list of 7 finite numbers (x, y, z, qw, qx, qy, qz)"), 7)
MAP_BODY_POSE = object_of(BODY_POSE, "an object of body poses")


# Every shape by its typedef's name (fsmscope/static/schema.js has one typedef per shape).
SHAPES: dict[str, Type] = {}


def shape(name: str, js: str, fields: tuple[Field, ...], check: Problem | None = None) -> Type:
    """An object of ``fields`` (extra fields allowed; ``check``: a check of its own instead), ``js``
    the name of its typedef in the browser."""
    t = Type(name, check or (lambda v: fields_problem(v, fields)), js=js, shape=fields)
    SHAPES[js] = t
    return t


def _join(where: str, problem: str) -> str:
    """``where`` followed by a nested problem: ``status.containers['/a'].active[0] must be ...``."""
    return where + (problem if problem[:1] in ("[", ".", " ") else " " + problem)


def fields_problem(obj: Any, fields: tuple[Field, ...], what: str = "") -> str | None:
    """The first field of ``obj`` that is missing or of the wrong type; ``what`` names ``obj``
    (empty for a nested object, whose problem then reads on from its parent's name)."""
    if type(obj) is not dict:
        return "%s must be an object, not %s" % (what, _what(obj))
    for f in fields:
        if f.name not in obj:
            if f.required:
                return "%s lacks '%s'" % (what, f.name)
            continue
        problem = f.type.check(obj[f.name])
        if problem:
            return _join("%s.%s" % (what, f.name), problem)
    return None


class _Absent:
    """An optional field not given to a maker: left out of what it makes."""

    def __repr__(self) -> str:
        return "ABSENT"


ABSENT: Any = _Absent()


def argument(name: str) -> str:
    """A field's name as a maker's parameter: ``from`` is ``from_``."""
    return name + "_" if keyword.iskeyword(name) else name


def maker(name: str, head: tuple[tuple[str, str], ...], fields: tuple[Field, ...], doc: str) -> Callable[..., dict]:
    """The function that makes one shape as a single dict literal: ``head``'s items first (key, Python
    expression: a constant, or a parameter of the same name), then ``fields``, the required ones in
    their order, then the optional ones, which default to ``ABSENT`` and are then left out.

    Generated, as a dataclass's ``__init__`` is from its fields, so that a field's name is written once
    (in its definition) and what a hot path makes costs no more than a hand-written literal. The
    source is made of this package's own names only."""
    required = [argument(f.name) for f in fields if f.required]
    optional = [(f.name, argument(f.name)) for f in fields if not f.required]
    params = [expr for key, expr in head if expr == key] + required + ["%s=ABSENT" % a for _, a in optional]
    items = ["%r: %s" % (key, expr) for key, expr in head]
    items += ["%r: %s" % (f.name, argument(f.name)) for f in fields if f.required]
    lines = ["def %s(%s):" % (name, ", ".join(params)), "    made = {%s}" % ", ".join(items)]
    lines += ["    if %s is not ABSENT:\n        made[%r] = %s" % (a, key, a) for key, a in optional]
    lines.append("    return made")
    scope: dict = {"ABSENT": ABSENT}
    exec("\n".join(lines), scope)
    made = scope[name]
    made.__doc__ = doc
    return made


def batch_maker(name: str, head: tuple[tuple[str, str], ...], fields: tuple[Field, ...]) -> Callable[..., list]:
    """``made(first_seq, items)``: the events of a batch, in order, the i-th stamped with seq
    ``first_seq + i``. An item is either an event made already (its seq is stamped) or a tuple of
    ``maker``'s arguments after the seq (a record of a step: fsm/observation/introspection.py), made
    into its event by the same dict literal ``maker`` would build, in one comprehension: no call per
    event. ``head`` must start with the version and the seq; at most one optional field."""
    optional = [f.name for f in fields if not f.required]
    assert [key for key, _ in head[:2]] == ["v", "seq"] and len(optional) <= 1
    params = [expr for key, expr in head if expr == key and key != "seq"] + [argument(f.name) for f in fields]
    where = {param: "item[%d]" % i for i, param in enumerate(params)}
    where["seq"] = "seq"
    items = ["%r: %s" % (key, where.get(expr, expr)) for key, expr in head]
    items += ["%r: %s" % (f.name, where[argument(f.name)]) for f in fields if f.required]
    literal = "{%s}" % ", ".join(items)
    if optional:
        last = where[argument(optional[0])]
        literal = "(%s if %s is ABSENT else {%s, %r: %s})" % (literal, last, ", ".join(items), optional[0], last)
    lines = ["def %s(first, items):" % name,
             "    return [_stamped(item, seq) if item.__class__ is dict else %s" % literal,
             "            for seq, item in zip(range(first, first + len(items)), items)]"]
    scope: dict = {"ABSENT": ABSENT, "_stamped": _stamped}
    exec("\n".join(lines), scope)
    return scope[name]


def _stamped(event: dict, seq: int) -> dict:
    event["seq"] = seq
    return event
