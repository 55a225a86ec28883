"""Breakpoint conditions: a small expression over a container's userdata keys.

``attempts > 2 and 'cube' in seen``, ``len(queue) == 0``, ``not done``, ``pose['z'] < 0.1``. The text
comes over the network, so it is never given to ``eval``: Python's parser (``ast.parse``, which only
builds a tree) reads it, every node is checked against a short list (names, literals, comparisons,
``and``/``or``/``not``, ``in``, ``+``/``-``, indexing by a literal, and ``len`` as the one call), and
this module walks the tree to evaluate it. A name is a userdata key, nothing else: there are no
builtins, attributes or other calls to reach. Anything else is refused with its column.
"""

from __future__ import annotations

import ast
import operator
import re
from typing import Any, Callable

MAX_LENGTH = 500  # characters of a condition
MAX_NODES = 200  # nodes of its tree
_LINES = re.compile("\r\n|\r|\n")  # the line breaks of Python's parser


class ConditionError(ValueError):
    """A condition that cannot be parsed, or cannot be evaluated on this userdata; ``column`` is
    where (1-based) when the text is at fault."""

    def __init__(self, message: str, column: int | None = None) -> None:
        super().__init__(message if column is None else "%s (column %d)" % (message, column))
        self.column = column


_COMPARE: dict[type, Callable[[Any, Any], Any]] = {
    ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le,
    ast.Gt: operator.gt, ast.GtE: operator.ge, ast.In: lambda a, b: a in b, ast.NotIn: lambda a, b: a not in b,
    ast.Is: operator.is_, ast.IsNot: operator.is_not}
_BINARY: dict[type, Callable[[Any, Any], Any]] = {ast.Add: operator.add, ast.Sub: operator.sub}
_UNARY: dict[type, Callable[[Any], Any]] = {ast.Not: operator.not_, ast.USub: operator.neg, ast.UAdd: operator.pos}
_LITERAL = (int, float, str, bool, type(None))
_WORDS = {ast.Call: "a call other than len(...)", ast.Attribute: "an attribute ('.')", ast.Lambda: "a lambda",
          ast.BinOp: "this operator (only + and -)", ast.IfExp: "'... if ... else ...'",
          ast.NamedExpr: "':='", ast.Starred: "'*'", ast.Dict: "a dict", ast.ListComp: "a comprehension",
          ast.GeneratorExp: "a comprehension", ast.SetComp: "a comprehension", ast.DictComp: "a comprehension",
          ast.JoinedStr: "an f-string", ast.Await: "'await'", ast.Yield: "'yield'", ast.Slice: "a slice"}


class Condition:
    """A parsed condition: ``evaluate(lookup)`` with ``lookup(key)`` giving a userdata value (KeyError
    when there is none) returns whether it holds."""

    def __init__(self, text: str) -> None:
        self.text = text
        self._tree = parse_tree(text)
        self.keys = sorted({n.id for n in ast.walk(self._tree) if isinstance(n, ast.Name) and n.id != "len"})

    def evaluate(self, lookup: Callable[[str], Any]) -> bool:
        """Raises ConditionError when a key is missing or an operation fails on the values."""
        try:
            return bool(_value(self._tree.body, lookup))
        except ConditionError:
            raise
        except Exception as exc:
            raise ConditionError("%s could not be evaluated: %s: %s" % (self.text, type(exc).__name__, exc)) from exc

    def __repr__(self) -> str:
        return "Condition(%r)" % self.text


def parse_tree(text: str) -> ast.Expression:
    """The checked tree of ``text``; raises ConditionError saying what is wrong and where."""
    if not isinstance(text, str) or not text.strip():
        raise ConditionError("a condition must be a non-empty text")
    if len(text) > MAX_LENGTH:
        raise ConditionError("a condition holds at most %d characters, not %d" % (MAX_LENGTH, len(text)))
    stripped = text.strip()
    lead = len(text) - len(text.lstrip())  # columns are counted in the text as given
    try:
        tree = ast.parse(stripped, mode="eval")
    except SyntaxError as err:
        column = None if err.offset is None else max(err.offset, 1) + lead
        raise ConditionError("not a condition: %s" % (err.msg,), column) from None
    nodes = list(ast.walk(tree))
    if len(nodes) > MAX_NODES:
        raise ConditionError("a condition holds at most %d parts, not %d" % (MAX_NODES, len(nodes)))
    for node in nodes:
        problem = _refusal(node)
        if problem:
            raise ConditionError(problem, _column(stripped, node) + lead)
    return tree


def _column(text: str, node: ast.AST) -> int:
    """The 1-based column in its line of ``text`` of the part of ``node`` that is refused: an operator's or
    a '.''s own, an index's, else where ``node`` begins (an operation begins with its left operand)."""
    lines = _LINES.split(text)
    if not 0 < getattr(node, "lineno", 0) <= len(lines):
        return getattr(node, "col_offset", 0) + 1
    line = lines[node.lineno - 1].encode()  # ast's offsets count the line's UTF-8 bytes

    def column(offset: int) -> int:
        return len(line[:offset].decode(errors="replace")) + 1

    if isinstance(node, (ast.BinOp, ast.Attribute)):
        before = node.left if isinstance(node, ast.BinOp) else node.value
        if before.end_lineno == node.lineno and before.end_col_offset is not None:
            after = line[before.end_col_offset:]
            return column(before.end_col_offset + len(after) - len(after.lstrip(b" \t)")))
    if isinstance(node, ast.Subscript) and node.slice.lineno == node.lineno:
        return column(node.slice.col_offset)
    return column(node.col_offset)


def _refusal(node: ast.AST) -> str | None:
    """Why ``node`` may not appear in a condition; None when it may."""
    if isinstance(node, ast.Call):
        if isinstance(node.func, ast.Name) and node.func.id == "len" and len(node.args) == 1 and not node.keywords:
            return None
        return "%s is not allowed" % _WORDS[ast.Call]
    if isinstance(node, ast.Name):
        if node.id.startswith("__"):
            return "a name beginning with '__' is not allowed"
        return None
    if isinstance(node, ast.Constant):
        return None if isinstance(node.value, _LITERAL) else "this literal is not allowed"
    if isinstance(node, ast.BinOp):
        return None if type(node.op) in _BINARY else "%s is not allowed" % _WORDS[ast.BinOp]
    if isinstance(node, ast.Subscript):
        return None if isinstance(node.slice, (ast.Constant, ast.UnaryOp)) else "an index must be a literal"
    allowed = (ast.Expression, ast.BoolOp, ast.And, ast.Or, ast.UnaryOp, ast.Compare, ast.List, ast.Tuple,
               ast.Set, ast.Load, *_COMPARE, *_UNARY, *_BINARY)
    if isinstance(node, allowed):
        return None
    return "%s is not allowed" % _WORDS.get(type(node), "'%s'" % type(node).__name__)


def _value(node: ast.AST, lookup: Callable[[str], Any]) -> Any:
    if isinstance(node, ast.Constant):
        return node.value
    if isinstance(node, ast.Name):
        try:
            return lookup(node.id)
        except KeyError:
            raise ConditionError("there is no userdata key '%s'" % node.id) from None
    if isinstance(node, ast.BoolOp):
        if isinstance(node.op, ast.And):
            result: Any = True
            for part in node.values:
                result = _value(part, lookup)
                if not result:
                    return result
            return result
        result = False
        for part in node.values:
            result = _value(part, lookup)
            if result:
                return result
        return result
    if isinstance(node, ast.UnaryOp):
        return _UNARY[type(node.op)](_value(node.operand, lookup))
    if isinstance(node, ast.BinOp):
        return _BINARY[type(node.op)](_value(node.left, lookup), _value(node.right, lookup))
    if isinstance(node, ast.Compare):
        left = _value(node.left, lookup)
        for op, right_node in zip(node.ops, node.comparators):
            right = _value(right_node, lookup)
            if not _COMPARE[type(op)](left, right):
                return False
            left = right
        return True
    if isinstance(node, ast.Call):  # len, the one call _refusal lets through
        return len(_value(node.args[0], lookup))
    if isinstance(node, ast.Subscript):
        return _value(node.value, lookup)[_value(node.slice, lookup)]
    if isinstance(node, (ast.List, ast.Tuple)):
        return [_value(e, lookup) for e in node.elts]
    if isinstance(node, ast.Set):
        return {_value(e, lookup) for e in node.elts}
    raise ConditionError("'%s' cannot be evaluated" % type(node).__name__)
