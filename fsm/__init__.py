"""fsm: a SMACH-compatible state machine runtime without ROS. ``import fsm as smach`` runs SMACH scripts."""

from .log import (loginfo, logwarn, logerr, logdebug, set_loggers, is_shutdown, set_shutdown_check)
from .exceptions import (SmachError, InvalidTransitionError, InvalidStateError, InvalidConstructionError,
                         InvalidUserCodeError)
from .util import has_smach_interface, cb_interface, CBInterface
from .user_data import UserData, Remapper, Const, get_const
from .state import State, CBState
from .container import Container
from .state_machine import StateMachine
from .concurrence import Concurrence
from .sequence import Sequence
from .iterator import Iterator
from .introspection import attach, add_global_hook, remove_global_hook, Reporter

__all__ = [
    "loginfo", "logwarn", "logerr", "logdebug", "set_loggers", "is_shutdown", "set_shutdown_check",
    "SmachError", "InvalidTransitionError", "InvalidStateError", "InvalidConstructionError", "InvalidUserCodeError",
    "has_smach_interface", "cb_interface", "CBInterface", "UserData", "Remapper", "Const", "get_const",
    "State", "CBState", "Container", "StateMachine", "Concurrence", "Sequence", "Iterator",
    "attach", "add_global_hook", "remove_global_hook", "Reporter",
]

from .recorder import Recorder  # noqa: E402  (recording: fsm.attach(sm, fsm.Recorder("run.jsonl")))
__all__.append("Recorder")
