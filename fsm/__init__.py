"""fsm: a SMACH-compatible state machine runtime without ROS. ``import fsm as smach`` runs SMACH scripts.

Four subpackages, one concept each: ``core`` (SMACH's states and containers), ``ros`` (what
smach_ros and ROS provided: bus, actionlib, ROS states), ``observation`` (event schema,
reporter, status) and ``logfiles`` (recorder, reader, summary, transcript). Every name users
import from ``fsm`` is here; the modules users import by their old flat paths (``fsm.bus``,
``fsm.recorder``, ...) are registered under those paths too.
"""

import importlib
import pkgutil
import sys

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
from .ros import bus
from .ros.bus import Bus, ServiceException, get_bus
from .ros.actionlib import GoalStatus, SimpleActionServer, SimpleActionClient
from .ros.service_state import ServiceState
from .ros.simple_action_state import SimpleActionState
from .ros.monitor_state import MonitorState
from .ros.condition_state import ConditionState
from .logfiles.recorder import Recorder
from . import core, debugging, logfiles, observation, ros

# The flat module paths of before the grouping (``from fsm.bus import get_bus``, ``fsm.log``) keep working.
for _package in (core, ros, observation, logfiles):
    for _found in pkgutil.iter_modules(_package.__path__):
        _module = importlib.import_module("%s.%s" % (_package.__name__, _found.name))
        sys.modules.setdefault("%s.%s" % (__name__, _found.name), _module)
        globals().setdefault(_found.name, _module)
del _package, _found, _module

__all__ = [
    "loginfo", "logwarn", "logerr", "logdebug", "set_loggers", "is_shutdown", "set_shutdown_check",
    "SmachError", "InvalidTransitionError", "InvalidStateError", "InvalidConstructionError", "InvalidUserCodeError",
    "has_smach_interface", "cb_interface", "CBInterface", "UserData", "Remapper", "Const", "get_const",
    "State", "CBState", "Container", "StateMachine", "Concurrence", "Sequence", "Iterator",
    "attach", "add_global_hook", "remove_global_hook", "Reporter", "Recorder",
    "bus", "Bus", "ServiceException", "get_bus", "GoalStatus", "SimpleActionServer", "SimpleActionClient",
    "ServiceState", "SimpleActionState", "MonitorState", "ConditionState",
]
