"""The one error of the ROS 1 client: what went wrong, in words a viewer's user can act on."""


class Ros1Error(Exception):
    """A ROS 1 master, node or message that fsmscope's client could not use: unreachable, a failure
    code with its reason, a type it does not know, fields that do not make the message."""
