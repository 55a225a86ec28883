"""Debugging a running machine: pause, resume, step, breakpoints (with conditions on userdata) and
forced outcomes, at transition boundaries. Standard library only, like the rest of ``fsm``."""

from .breakpoint import Breakpoint, BreakpointError
from .condition import Condition, ConditionError
from .debugger import DebugError, Debugger, Hold, debugger_of


__all__ = ["Breakpoint", "BreakpointError", "Condition", "ConditionError", "DebugError", "Debugger", "Hold",
           "debugger_of"]
