"""A private ROS 1 for a test (fsmscope/server/testing/ros1.py: a real ``rosmaster`` on a free port,
what a node needs to run the original SMACH with smach_ros there, the real ``rostopic``), a robot's
process as a node of it (the dashboard's URL it prints, its outcome, its console).

A robot runs on this environment's Python (where fsmscope is installed) with Debian's packages after
its own on ``sys.path``, as ``--system-site-packages`` would put them: ours win where both have a
package (yaml, pygments).
"""

from __future__ import annotations

import contextlib
import re
import subprocess
import sys
import threading
import urllib.parse
from pathlib import Path
from typing import Iterator

import httpx
import pytest
from fsmscope.server.testing import ros1
from fsmscope.server.testing.demo_process import interrupt
from fsmscope.server.testing.polling import wait_for
from fsmscope.server.testing.ros1 import DEBIAN_PACKAGES, missing_ros1

ROBOTS = Path(__file__).resolve().parent / "robots"

# What ``python -c`` runs before a robot's script: Debian's packages after this environment's, then
# the script as ``python SCRIPT ARGS...`` would run it.
_WITH_DEBIAN_PACKAGES_LAST = (
    "import runpy, sys; sys.path.append(%r); sys.argv[:] = sys.argv[1:]; "
    "runpy.run_path(sys.argv[0], run_name='__main__')" % DEBIAN_PACKAGES)


def skip_without_ros1() -> None:
    """Skip, saying why, where the original SMACH (../shared/reference) or Debian's ROS 1 is absent."""
    reason = missing_ros1()
    if reason is not None:
        pytest.skip(reason)


DASHBOARD_LINE = r"^dashboard: (http://\S+)$"  # what a robot serving fsmscope's dashboard prints first


class Ros1(ros1.Ros1):
    """A private ROS 1 whose nodes can be tests/robots/'s robots."""

    def robot(self, script: str, *args: str, ready: str = DASHBOARD_LINE) -> Robot:
        """``python tests/robots/SCRIPT ARGS...`` as a node of this master, once it printed a line that
        matches ``ready``."""
        return Robot(self.robot_argv(script, *args), self.robot_env(), self.home, ready)

    def robot_argv(self, script: str, *args: str) -> list[str]:
        return [sys.executable, "-c", _WITH_DEBIAN_PACKAGES_LAST, str(ROBOTS / script), *args]

    def recorded(self, bag: Path, script: str, *args: str, timeout: float = 120) -> str:
        """``python tests/robots/SCRIPT ARGS...`` run to its end while the real ``rosbag record -a``
        records this master's topics into ``bag``; what the robot printed."""
        recorder = subprocess.Popen(["rosbag", "record", "-a", "-O", str(bag)], env=self.ros_env(), cwd=self.home,
                                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                    start_new_session=True)
        try:
            robot = subprocess.run(self.robot_argv(script, *args), env=self.robot_env(), cwd=self.home,
                                   capture_output=True, text=True, timeout=timeout)
        finally:
            interrupt(recorder, 20)  # rosbag closes the bag on SIGINT, as on Ctrl-C
        said = recorder.stdout.read()
        assert robot.returncode == 0 and bag.exists(), robot.stdout + robot.stderr + said
        return robot.stdout


class Robot:
    """A robot's process, in a group of its own: ``url``, what the first line that matched ``ready``
    said (the dashboard's address of a robot that serves one: ``dashboard: URL``); ``output``, all it
    printed (both streams, in order) so far."""

    def __init__(self, argv: list[str], env: dict[str, str], cwd: Path, ready: str = DASHBOARD_LINE) -> None:
        self.proc = subprocess.Popen(argv, env=env, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True, start_new_session=True)
        self._lines: list[str] = []
        self._ready = re.compile(ready, re.M)
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        try:
            self.url = wait_for(self._printed_ready, 60, interval=0.05, what=lambda: "the robot to print %r:\n%s"
                                % (ready, self.output))
        except (RuntimeError, TimeoutError):
            self.stop()
            raise

    def _read(self) -> None:
        for line in self.proc.stdout:
            self._lines.append(line)

    @property
    def output(self) -> str:
        return "".join(self._lines)

    def _printed_ready(self) -> str | None:
        found = self._ready.search(self.output)
        if found is None and self.proc.poll() is not None:
            raise RuntimeError("the robot exited with %d before it was ready:\n%s" % (self.proc.returncode,
                                                                                        self.output))
        return (found.group(1) if found.groups() else found.group(0)) if found else None

    def api(self) -> httpx.Client:
        """A client of the robot's dashboard, holding the token its URL carries."""
        base, query = self.url.split("/?", 1)
        token = urllib.parse.parse_qs(query)["token"][0]
        return httpx.Client(base_url=base, headers={"Authorization": "Bearer " + token}, timeout=10)

    def outcome(self, timeout: float = 30) -> str:
        """The top machine's outcome, once the robot printed it (``outcome: OUTCOME``)."""
        def printed() -> str | None:
            found = re.search(r"^outcome: (\S+)$", self.output, re.M)
            return found.group(1) if found else None
        return wait_for(printed, timeout, interval=0.05, what=lambda: "the robot's outcome:\n" + self.output)

    def stop(self, timeout: float = 20) -> int:
        """SIGINT, as Ctrl-C or roslaunch would: rospy shuts the node down; returns the exit code."""
        interrupt(self.proc, timeout)
        self._reader.join(5)
        return self.proc.returncode


_ROSPY_LINE = re.compile(r"^\[(INFO|WARN|ERROR|DEBUG)\] \[[0-9.]+\]: (.*)$")


def rospy_lines(output: str) -> list[tuple[str, str]]:
    """``(level, message)`` of each line rospy printed to the console (``[INFO] [TIME]: MESSAGE``); the
    lines of a message after its first start with a tab (SMACH's userdata keys), as in a transcript."""
    return logged_lines(output, _ROSPY_LINE)


def logged_lines(output: str, first_line: re.Pattern) -> list[tuple[str, str]]:
    """``(level, message)`` of each message in ``output`` whose first line ``first_line`` matches (its
    groups: the level, the text); its next lines are those that follow it starting with a tab."""
    lines: list[tuple[str, str]] = []
    in_message = False
    for text in output.splitlines():
        found = first_line.match(text)
        if found:
            lines.append((found.group(1).strip().lower(), found.group(2)))
        elif in_message and text.startswith("\t"):
            lines[-1] = (lines[-1][0], lines[-1][1] + "\n" + text)
        in_message = bool(found) or (in_message and text.startswith("\t"))
    return lines


READY = r"^ready$"  # what tests/robots/smach_ros_loop.py (and smach_ros_robot.py) prints once it publishes


@contextlib.contextmanager
def two_robots(ros: Ros1) -> Iterator[dict[str, Robot]]:
    """Robots nobody may change (tests/robots/smach_ros_loop.py): r1 (node /robot1, server /r1, stop
    topic /r1/sm_stop) and r2 (node /robot2, ...), by their machines' names; the dict may be given
    new robots, which are stopped too."""
    robots = {name: ros.robot("smach_ros_loop.py", node, "/" + name, "/%s/sm_stop" % name, ready=READY)
              for name, node in (("r1", "robot1"), ("r2", "robot2"))}
    try:
        yield robots
    finally:
        for robot in robots.values():
            robot.stop()


class Live:
    """A real ``fsmscope ros1`` process following ``ros``'s master, recording to ``recording``, each
    robot of ``two_robots`` preempted on its own stop topic."""

    def __init__(self, ros: Ros1, recording: Path) -> None:
        from fleet_support import started

        self.recording = recording
        self.proc, found = started(["ros1", "--master", ros.master_uri, "--port", "0", "--record", str(recording),
                                    "--stop-topic", "r1=/r1/sm_stop", "--stop-topic", "r2=/r2/sm_stop"],
                                   r"dashboard at (http://\S+)")
        self.url = found.group(1)
        self.base, self.token = self.url.split("/?token=")

    def get(self, path: str, **params) -> httpx.Response:
        return httpx.get(self.base + path, params={"token": self.token, **params}, timeout=10)

    def post(self, path: str, body: dict) -> httpx.Response:
        return httpx.post(self.base + path, params={"token": self.token}, json=body, timeout=10)

    def machines(self) -> dict[str, dict]:
        return {m["name"]: m for m in self.get("/api/machines").json()}

    def events(self, name: str, kinds: str = "start,transition,terminate,control") -> list[dict]:
        answer = self.get("/api/machines/%s/history" % name, kinds=kinds, limit=10000)
        assert answer.status_code == 200, answer.text
        return answer.json()["events"]


@contextlib.contextmanager
def live_viewer(ros: Ros1) -> Iterator[Live]:
    """``Live`` once it shows both robots' machines; stopped at the end."""
    from fleet_support import stop

    viewer = Live(ros, ros.home / "live.jsonl")
    try:
        wait_for(lambda: {"r1", "r2"} <= set(viewer.machines()), 30, interval=0.1,
                 what=lambda: "both robots' machines on the dashboard: %s" % viewer.machines())
        yield viewer
    finally:
        stop(viewer.proc)
