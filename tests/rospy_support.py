"""rospy nodes a test of fsmscope's ROS 1 client runs against a private master (tests/ros1_support.py):
tests/robots/rospy_node.py on Debian's Python, where rospy lives, with smach_msgs' generated classes."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import threading
from pathlib import Path

from fsmscope.server.testing.polling import wait_for

from ros1_support import Ros1

SCRIPT = Path(__file__).resolve().parent / "robots" / "rospy_node.py"


class RospyNode:
    """``rospy_node.py NAME ARGS...`` as a node of ``ros``'s master, started and ready (it printed so)."""

    def __init__(self, ros: Ros1, name: str, *args: str) -> None:
        self.name = name
        self.proc = subprocess.Popen(["/usr/bin/python3", str(SCRIPT), name, *args], env=ros.robot_env(),
                                     cwd=ros.home, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                     start_new_session=True)
        self._lines: list[str] = []
        threading.Thread(target=self._read, daemon=True).start()
        wait_for(self._ready, 30, interval=0.02, what=lambda: "rospy node %s to be ready:\n%s" % (name, self.output))

    def _read(self) -> None:
        for line in self.proc.stdout:
            self._lines.append(line)

    def _ready(self) -> bool:
        if self.proc.poll() is not None:
            raise RuntimeError("rospy node %s exited with %d:\n%s" % (self.name, self.proc.returncode, self.output))
        return "ready\n" in self._lines

    @property
    def output(self) -> str:
        return "".join(self._lines)

    def messages(self) -> list[dict]:
        """What an ``echo`` node received, one dict per message (times in seconds, bytes as base64)."""
        return [json.loads(line) for line in list(self._lines) if line.startswith("{")]

    def kill(self) -> None:
        """SIGKILL, as a robot that crashes: it unregisters nothing, the OS closes its connections."""
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
        self.proc.wait(10)
