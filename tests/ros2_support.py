"""A private ROS 2 domain for a test, and robots on it (tests/robots/ros2_robot.py) as processes.

Each test takes a domain id no other test on this machine holds (a lock file per id, so xdist's
workers and other runs never meet). The robots configure Cyclone DDS through ``CYCLONEDDS_URI``, as
a ROS 2 robot with rmw_cyclonedds does, with their own XML (not fsmscope.ros2.config's): the
loopback only, multicast off, the loopback as the one peer, and a participant lease of
ROBOT_LEASE s (Cyclone's default is 10 s) so that a robot killed is seen gone within seconds.
"""

from __future__ import annotations

import fcntl
import os
import random
import signal
import subprocess
import sys
import tempfile
import threading
from pathlib import Path

import pytest

from fsmscope.server.testing.demo_process import interrupt
from fsmscope.server.testing.polling import wait_for

ROBOTS = Path(__file__).resolve().parent / "robots"
REFERENCE = Path(__file__).resolve().parents[2] / "shared/reference/executive_smach/ros2"
ROBOT_LEASE = 2.0
ROBOT_CYCLONE_CONFIG = (
    '<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface address="127.0.0.1"/></Interfaces>'
    "<AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex>"
    f'<Peers><Peer address="127.0.0.1"/></Peers><LeaseDuration>{ROBOT_LEASE:g}s</LeaseDuration></Discovery>'
    "</Domain></CycloneDDS>")
STATUS = "smach_msgs/msg/SmachContainerStatus"
STRUCTURE = "smach_msgs/msg/SmachContainerStructure"
STATUS_TOPIC = "/robot/smach/container_status"


def skip_without_reference() -> None:
    """Skip, saying why, where executive_smach's ros2 branch (../shared/reference) is absent."""
    if not (REFERENCE / "smach_ros/smach_ros/introspection.py").exists():
        pytest.skip(f"executive_smach's ros2 branch is not at {REFERENCE} (../shared/reference)")


class PrivateDomain:
    """A ROS 2 domain id held by this process alone until ``release``."""

    def __init__(self) -> None:
        ids = list(range(1, 233))
        random.shuffle(ids)
        for domain_id in ids:
            lock = open(Path(tempfile.gettempdir()) / f"fsmscope-ros2-domain-{domain_id}.lock", "w")
            try:
                fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                lock.close()
                continue
            self.id, self._lock = domain_id, lock
            return
        raise RuntimeError("every ROS 2 domain id is held by another test")

    def release(self) -> None:
        self._lock.close()


class Robot:
    """``tests/robots/ros2_robot.py DOMAIN MODE`` in a process group of its own; ``output``, all it
    printed so far (both streams, in order)."""

    def __init__(self, domain_id: int, mode: str = "smach") -> None:
        env = dict(os.environ, CYCLONEDDS_URI=ROBOT_CYCLONE_CONFIG, PYTHONUNBUFFERED="1")
        self.proc = subprocess.Popen([sys.executable, str(ROBOTS / "ros2_robot.py"), str(domain_id), mode], env=env,
                                     stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                     start_new_session=True)
        self._lines: list[str] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        try:
            self.wait_for_line("ready", 60)
        except (RuntimeError, TimeoutError):
            self.stop()
            raise

    def _read(self) -> None:
        for line in self.proc.stdout:
            self._lines.append(line.rstrip("\n"))

    @property
    def output(self) -> str:
        return "\n".join(self._lines)

    def printed(self, line: str) -> bool:
        return line in self._lines

    def wait_for_line(self, line: str, timeout: float = 20) -> None:
        def seen() -> bool:
            if line in self._lines:
                return True
            if self.proc.poll() is not None:
                raise RuntimeError(f"the robot exited with {self.proc.returncode} before printing {line!r}:\n{self.output}")
            return False
        wait_for(seen, timeout, interval=0.02, what=lambda: f"the robot to print {line!r}:\n{self.output}")

    def kill(self) -> None:
        """SIGKILL, as a crash or a power cut: the robot's participant says nothing on its way out."""
        os.killpg(self.proc.pid, signal.SIGKILL)
        self.proc.wait()

    def stop(self, timeout: float = 10) -> int:
        interrupt(self.proc, timeout)
        self._reader.join(5)
        return self.proc.returncode
