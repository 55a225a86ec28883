"""smach, for a script run by ``fsmscope run`` where the original is not installed (loaded under the
name ``smach``): the names of SMACH's core, from fsm (docs/coming-from-smach.md says what differs)."""

from fsm import (CBInterface, CBState, Concurrence, Container, InvalidConstructionError, InvalidStateError,
                 InvalidTransitionError, InvalidUserCodeError, Iterator, Remapper, Sequence, SmachError, State,
                 StateMachine, UserData, cb_interface, has_smach_interface, is_shutdown, logdebug, logerr, loginfo,
                 logwarn, set_loggers, set_shutdown_check)

__all__ = ["CBInterface", "CBState", "Concurrence", "Container", "InvalidConstructionError", "InvalidStateError",
           "InvalidTransitionError", "InvalidUserCodeError", "Iterator", "Remapper", "Sequence", "SmachError",
           "State", "StateMachine", "UserData", "cb_interface", "has_smach_interface", "is_shutdown", "logdebug",
           "logerr", "loginfo", "logwarn", "set_loggers", "set_shutdown_check"]
