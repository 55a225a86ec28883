"""What a command raises when it cannot start with the arguments given: its own module, since every
command's start-up may raise it and the one entry point (fsmscope/server/cli/__init__.py) answers it."""


class CannotServe(Exception):
    """The command cannot start with these arguments (the port is taken, a public address has no
    token, Zenoh cannot open its session): it ends with exit code 1 and this reason."""
