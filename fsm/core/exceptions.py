"""SMACH's exceptions: each logs ``"<ClassName>: <message>"`` at ERROR level when constructed."""

from . import log


class SmachError(Exception):
    """Base of every runtime error; logged on construction, as SMACH does."""

    def __init__(self, message: str) -> None:
        log.logerr(type(self).__name__ + ": " + message)
        Exception.__init__(self, message)


class InvalidStateError(SmachError):
    pass


class InvalidTransitionError(SmachError):
    pass


class InvalidUserCodeError(SmachError):
    pass


class InvalidConstructionError(SmachError):
    pass
