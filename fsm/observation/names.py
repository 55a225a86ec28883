"""A machine's name: one rule wherever a name travels, and how to make a name that keeps it.

A name goes into the hub's registry and the page's address (``/api/machines/<name>``, ``#m=<name>``),
a Zenoh key (``fsmscope/<robot>/<name>/events``: one key chunk), an MCAP topic and a Foxglove
channel (``/fsmscope/<name>/events``), and every event's ``machine`` field. So a name is 1 to
``MAX_NAME`` characters, without the characters that would split or end it in one of those
(``/`` a key's or a topic's or a path's separator, ``* $`` Zenoh's wildcards, ``? #`` a URL's query
and fragment, and Zenoh's too), without control characters, and without a space at either end.

``valid`` makes a name that keeps the rule out of any text (a script's file name, an introspection
server's ROS name); ``unique`` makes it differ from the names already taken, the one way every
namer does it: ``name``, ``name-2``, ``name-3``... The event schema's ``machine`` field and the
fleet's key chunks check this rule, and ``fsmscope/static/schema.js`` carries it to the page
(``python -m server.schema_export``).

Standard library only, like the rest of ``fsm``.
"""

from __future__ import annotations

import re
from typing import Callable, Container

MAX_NAME = 200
RESERVED = "/*$?#"
REPLACEMENT = "_"  # what ``valid`` puts for a character a name cannot hold
FALLBACK = "machine"  # the name ``valid`` makes of a text that has no usable character
FORBIDDEN = RESERVED + "".join(map(chr, range(0x20))) + "\x7f"  # the reserved and the control characters
_FORBIDDEN = re.compile("[%s]" % re.escape(FORBIDDEN))


def problem(name: object) -> str | None:
    """What is wrong with ``name`` as a machine's name, in words (None: nothing)."""
    if type(name) is not str:
        return "must be a string"
    if not name:
        return "must not be empty"
    if len(name) > MAX_NAME:
        return "must be at most %d characters, not %d" % (MAX_NAME, len(name))
    if name[0] == " " or name[-1] == " ":
        return "must not begin or end with a space"
    bad = _FORBIDDEN.search(name)
    if bad:
        return "must not hold %r (no / * $ ? #, no control character)" % bad.group()
    return None


def is_valid(name: object) -> bool:
    return problem(name) is None


def check(name: str, what: str = "machine") -> str:
    """``name`` when it keeps the rule; ValueError saying why when it does not."""
    wrong = problem(name)
    if wrong:
        raise ValueError("a %s's name %s: %r" % (what, wrong, name))
    return name


def valid(text: str, reserve: int = 0) -> str:
    """A name made of ``text``: each character a name cannot hold becomes ``_``, outer spaces go,
    and it is cut so that ``reserve`` more characters (a suffix of ``unique``) still fit."""
    name = _FORBIDDEN.sub(REPLACEMENT, text).strip(" ")[:MAX_NAME - reserve].rstrip(" ")
    return name or FALLBACK


def unique(text: str, taken: Container[str] | Callable[[str], bool]) -> str:
    """A valid name made of ``text`` that is not ``taken`` (a set of names, or a test): the name
    itself when free, else ``name-2``, ``name-3``..."""
    is_taken = taken if callable(taken) else taken.__contains__
    name = valid(text)
    i = 1
    while is_taken(name):
        i += 1
        suffix = "-%d" % i
        name = valid(text, len(suffix)) + suffix
    return name
