"""Text from outside (a log, a bag, a machine's paths and messages) as fsmscope shows it: each
control character as a sign, seen and never obeyed. A terminal obeys ESC (colours, the window's
title, clearing the screen), CSI (U+009B, in some terminals), BEL, BS and CR (writing over what a
line said); XML cannot hold them. The graph's labels (fsmscope/server/graph.py) and every line the command
line prints from a log or a bag (fsmscope/server/cli/) use this one rule: C0 characters and DEL as their
Unicode control pictures (U+2400 + code, U+2421: ESC is ␛), the C1 characters and the
non-characters U+FFFE, U+FFFF as U+FFFD."""

from __future__ import annotations

_SIGNS = {c: 0x2400 + c for c in range(0x20)}
_SIGNS.update({0x7F: 0x2421, 0xFFFE: 0xFFFD, 0xFFFF: 0xFFFD})
_SIGNS.update({c: 0xFFFD for c in range(0x80, 0xA0)})
_LAYOUT = {ord("\n"): None, ord("\t"): None}
_TERMINAL_SIGNS = {c: sign for c, sign in _SIGNS.items() if c not in _LAYOUT}


def visible(text: object) -> str:
    """``text`` with every control character as its sign, newline and tab too (a label is one line)."""
    return str(text).translate(_SIGNS)


def terminal_text(text: object) -> str:
    """``text`` as a terminal shows it: newline and tab kept (SMACH's own lines hold them: a
    Concurrence's userdata on a line of its own), every other control character as its sign."""
    return str(text).translate(_TERMINAL_SIGNS)
