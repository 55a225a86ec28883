"""fsm: a SMACH-compatible state machine runtime without ROS. ``import fsm as smach`` runs SMACH scripts.

Subpackages, one concept each: ``core`` (SMACH's states and containers), ``ros`` (what
smach_ros and ROS provided: bus, actionlib, ROS states), ``observation`` (event schema,
reporter, status), ``logfiles`` (recorder, reader, summary, transcript), ``debugging`` and
``control``. Every name users import from ``fsm`` is here; a module is imported by one path
only, its subpackage's (``fsm.ros.bus``, ``fsm.logfiles.recorder``).
"""

from .core.log import (loginfo, logwarn, logerr, logdebug, set_loggers, is_shutdown, set_shutdown_check)
from .core.exceptions import (SmachError, InvalidTransitionError, InvalidStateError, InvalidConstructionError,
                              InvalidUserCodeError)
from .core.util import has_smach_interface, cb_interface, CBInterface
from .core.user_data import UserData, Remapper, Const, get_const
from .core.state import State, CBState
from .core.container import Container
from .core.state_machine import StateMachine
from .core.concurrence import Concurrence
from .core.sequence import Sequence
from .core.iterator import Iterator
from .observation.introspection import attach, add_global_hook, remove_global_hook, Reporter
from .ros.bus import Bus, ServiceException, get_bus
from .ros.actionlib import GoalStatus, SimpleActionServer, SimpleActionClient
from .ros.service_state import ServiceState
from .ros.simple_action_state import SimpleActionState
from .ros.monitor_state import MonitorState
from .ros.condition_state import ConditionState
from .logfiles.recorder import Recorder
from . import core, debugging, logfiles, observation, ros

__all__ = [
    "loginfo", "logwarn", "logerr", "logdebug", "set_loggers", "is_shutdown", "set_shutdown_check",
    "SmachError", "InvalidTransitionError", "InvalidStateError", "InvalidConstructionError", "InvalidUserCodeError",
    "has_smach_interface", "cb_interface", "CBInterface", "UserData", "Remapper", "Const", "get_const",
    "State", "CBState", "Container", "StateMachine", "Concurrence", "Sequence", "Iterator",
    "attach", "add_global_hook", "remove_global_hook", "Reporter", "Recorder",
    "Bus", "ServiceException", "get_bus", "GoalStatus", "SimpleActionServer", "SimpleActionClient",
    "ServiceState", "SimpleActionState", "MonitorState", "ConditionState",
]
