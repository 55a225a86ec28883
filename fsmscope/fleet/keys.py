"""The fleet's key space on Zenoh: ``fsmscope/<robot>/<machine>/...``. Robot and machine names are
single key chunks: they keep the one name rule (fsm/observation/names.py), which refuses the
characters Zenoh gives a meaning to (``/ * $ ? #``)."""

from __future__ import annotations

from fsm.observation import names

PREFIX = "fsmscope"


def chunk(name: str, what: str) -> str:
    """``name`` as one chunk of a key; ValueError when it cannot be one."""
    return names.check(name, what)


def robot_chunk(name: str) -> str:
    """A robot's name as a key chunk, without ``:`` too: a dashboard names the robot's machines
    ``<robot>:<machine>`` (fsmscope/fleet/watcher.py ``fleet_name``) and reads the robot back up to the first one."""
    if ":" in chunk(name, "robot"):
        raise ValueError("a robot's name must not hold ':' (a dashboard names its machines <robot>:<machine>): %r"
                         % name)
    return name


def machine_key(robot: str, machine: str) -> str:
    """The machine's own key: its liveliness token (alive while its process is)."""
    return "%s/%s/%s" % (PREFIX, chunk(robot, "robot"), chunk(machine, "machine"))


def events_key(robot: str, machine: str) -> str:
    """Where the machine's events are put, in batches (a JSON list)."""
    return machine_key(robot, machine) + "/events"


def state_key(robot: str, machine: str) -> str:
    """The queryable that answers the machine's snapshot event (its whole state now)."""
    return machine_key(robot, machine) + "/state"


def history_key(robot: str, machine: str) -> str:
    """The queryable that answers ``?since=SEQ`` with the events from SEQ on that the robot keeps."""
    return machine_key(robot, machine) + "/history"


def control_key(robot: str, machine: str) -> str:
    """The queryable that applies a control to the machine (fsmscope/fleet/control.py) and answers its result."""
    return machine_key(robot, machine) + "/control"


def beat_key(session_id: str, robot: str) -> str:
    """Where a dashboard puts its heartbeats for ``robot`` while it leases one of its machines
    (fsmscope/fleet/beats.py). Outside ``fsmscope/``: no dashboard is taken for a machine."""
    return "%s-dashboards/%s/%s" % (PREFIX, chunk(session_id, "dashboard"), chunk(robot, "robot"))


def beats_for(robot: str) -> str:
    """Every dashboard's heartbeats for ``robot``."""
    return "%s-dashboards/*/%s" % (PREFIX, chunk(robot, "robot"))


def beat_sender(key: str) -> str:
    """The dashboard's session id of a heartbeat's key."""
    return key.split("/")[1]


ALL_MACHINES = PREFIX + "/*/*"
ALL_EVENTS = PREFIX + "/*/*/events"


def split(key: str) -> tuple[str, str]:
    """(robot, machine) of any of a machine's keys."""
    parts = key.split("/")
    return parts[1], parts[2]
