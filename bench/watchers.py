"""The watchers the benches that set fsm beside the original SMACH attach to a machine, and that
original: smach_ros's IntrospectionServer's work in the machine's thread (``smach_ros_cost``),
fsmscope's in-process watch as ``fsmscope run`` composes it (``Watched``), the original core
loaded from ../shared/reference (``load_original``) and the userdata both run with. Shared by
bench/original_smach.py and bench/watched.py."""

from __future__ import annotations

import base64
import os
import pickle
import sys
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

import fsm
from fsm.logfiles import recorder
from fsmscope.server.cli.zenoh_options import robot_follows
from fsmscope.server.http_server import ServerThread

if TYPE_CHECKING:
    from fsmscope.fleet.robot import ZenohRobot

ORIGINAL_SRC = Path(__file__).resolve().parent.parent.parent / "shared/reference/executive_smach/noetic/smach/src"
USERDATA = {"count": 0, "pose": [0.1 * i for i in range(7)], "name": "pick the red cube"}


def load_original(bench: str) -> Any:
    """The original smach, imported under its own name from ../shared/reference; without it, ``bench``
    is skipped (exit status 0, so that `make bench` goes on), saying why."""
    if not (ORIGINAL_SRC / "smach" / "__init__.py").exists():
        print("%s: skipped: it needs the original SMACH at %s (shared/ beside the project)" % (bench, ORIGINAL_SRC),
              file=sys.stderr, flush=True)
        sys.exit(0)
    sys.path.insert(0, str(ORIGINAL_SRC))
    import smach
    return smach


def containers(machine: Any) -> list:
    """The machine and every container below it."""
    found = [machine]
    for child in machine.get_children().values():
        if hasattr(child, "get_children"):
            found += containers(child)
    return found


def smach_ros_cost(machine: Any) -> None:
    """smach_ros's IntrospectionServer's work in the machine's thread: its ContainerProxy registers a
    start, transition and termination callback on every container, and each one pickles and
    base64-encodes that container's userdata for the status message."""
    for container in containers(machine):
        def status(*args: Any, container: Any = container) -> None:
            base64.b64encode(pickle.dumps(container.userdata._data, 2)).decode("utf-8")
        container.register_start_cb(status)
        container.register_transition_cb(status)
        container.register_termination_cb(status)


class Watched:
    """fsmscope's in-process watch, as ``fsmscope run`` attaches it to a machine: a recorder (to a
    temporary log) and the hub of a real server; with ``robot``, the Zenoh robot publishing what the
    hub encodes (``run --zenoh``; a server started with a Foxglove server fed from its hub is
    ``--foxglove``). ``slowed``: the recorder's flush interval is that many times longer (under
    callgrind)."""

    def __init__(self, server: ServerThread, slowed: int = 1, robot: ZenohRobot | None = None) -> None:
        self.server = server
        self.robot = robot
        fd, self.path = tempfile.mkstemp(suffix=".jsonl")
        os.close(fd)
        self.recorder = fsm.Recorder(self.path, flush_interval=recorder.DEFAULT_FLUSH_INTERVAL * slowed)
        self.name: str | None = None
        self.reporter: Any = None

    def attach(self, machine: Any) -> None:
        # Named by the recorder's attach, as `fsmscope run`'s runner names them: the hub keeps the name.
        self.reporter = fsm.attach(machine, self.recorder, name="bench-%d" % time.monotonic_ns())
        entry = self.server.hub.add_local(machine)
        self.name = entry.name
        if self.robot is not None:
            robot_follows(self.robot, entry)

    def close(self) -> None:
        self.server.hub.remove(self.name)
        self.recorder.close()
        for leftover in (self.path, self.path + ".idx"):
            if os.path.exists(leftover):
                os.unlink(leftover)
