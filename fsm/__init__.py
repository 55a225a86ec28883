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
from . import bus
from .bus import Bus, ServiceException, get_bus
from .actionlib import GoalStatus, SimpleActionServer, SimpleActionClient
from .service_state import ServiceState
from .simple_action_state import SimpleActionState
from .monitor_state import MonitorState
from .condition_state import ConditionState
from .recorder import Recorder

__all__ = [
    "loginfo", "logwarn", "logerr", "logdebug", "set_loggers", "is_shutdown", "set_shutdown_check",
    "SmachError", "InvalidTransitionError", "InvalidStateError", "InvalidConstructionError", "InvalidUserCodeError",
    "has_smach_interface", "cb_interface", "CBInterface", "UserData", "Remapper", "Const", "get_const",
    "State", "CBState", "Container", "StateMachine", "Concurrence", "Sequence", "Iterator",
    "attach", "add_global_hook", "remove_global_hook", "Reporter", "Recorder",
    "bus", "Bus", "ServiceException", "get_bus", "GoalStatus", "SimpleActionServer", "SimpleActionClient",
    "ServiceState", "SimpleActionState", "MonitorState", "ConditionState",
]
