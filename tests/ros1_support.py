"""A private ROS 1 for a test: a real ``rosmaster`` on a free port, what a node needs to run the
original SMACH with smach_ros there, a robot's process as a node of it (the dashboard's URL it
prints, its outcome, its console) and the real ``rostopic``.

ROS 1 comes from Debian's packages (``make apt``): rospy, rosmaster and rostopic live in Debian's
Python (/usr/lib/python3/dist-packages). The original SMACH, smach_ros and smach_msgs' .msg files
come from ``../shared/reference`` beside the project root (its README); smach_msgs' Python classes
are generated from them with genpy, as catkin would. A robot runs on this environment's Python (where
fsmscope is installed) with Debian's packages after its own on ``sys.path``, as ``--system-site-packages``
would put them: ours win where both have a package (yaml, pygments).
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import threading
import urllib.parse
from pathlib import Path

import httpx
import pytest
from fsmscope.server.testing.demo_process import free_port, interrupt
from fsmscope.server.testing.polling import wait_for

ROOT = Path(__file__).resolve().parents[1]
NOETIC = ROOT.parent / "shared/reference/executive_smach/noetic"
DEBIAN_PACKAGES = "/usr/lib/python3/dist-packages"
GENMSG_PY = "/usr/lib/genpy/genmsg_py.py"
STD_MSGS = "/usr/share/std_msgs/msg"
ROBOTS = Path(__file__).resolve().parent / "robots"

# What ``python -c`` runs before a robot's script: Debian's packages after this environment's, then
# the script as ``python SCRIPT ARGS...`` would run it.
_WITH_DEBIAN_PACKAGES_LAST = (
    "import runpy, sys; sys.path.append(%r); sys.argv[:] = sys.argv[1:]; "
    "runpy.run_path(sys.argv[0], run_name='__main__')" % DEBIAN_PACKAGES)


def skip_without_ros1() -> None:
    """Skip, saying why, where the original SMACH (../shared/reference) or Debian's ROS 1 is absent."""
    if not (NOETIC / "smach_ros" / "package.xml").exists():
        pytest.skip("the original SMACH and smach_ros are not at %s (a copy of shared/ beside the project root)"
                    % NOETIC)
    missing = [tool for tool in ("rosmaster", "rostopic") if shutil.which(tool) is None]
    missing += [path for path in (GENMSG_PY, STD_MSGS) if not os.path.exists(path)]
    if missing:
        pytest.skip("ROS 1 is not installed (make apt installs Debian's packages): no %s" % ", ".join(missing))


def generate_smach_msgs(out: Path) -> Path:
    """smach_msgs' Python classes, generated from the original's .msg files into ``out``; returns
    the folder to put on PYTHONPATH."""
    msg_dir = NOETIC / "smach_msgs" / "msg"
    package = out / "smach_msgs"
    common = ["-p", "smach_msgs", "-o", str(package / "msg")]
    subprocess.run(["/usr/bin/python3", GENMSG_PY, *common, "-Ismach_msgs:%s" % msg_dir, "-Istd_msgs:%s" % STD_MSGS,
                    *map(str, sorted(msg_dir.glob("*.msg")))], check=True, capture_output=True)
    subprocess.run(["/usr/bin/python3", GENMSG_PY, "--initpy", *common], check=True, capture_output=True)
    (package / "__init__.py").touch()
    return out


class Ros1:
    """A rosmaster of its own (``start``, ``stop``) and the environment its nodes run in, all under ``home``."""

    def __init__(self, home: Path) -> None:
        self.home = home
        self.port = free_port()
        self.master_uri = "http://127.0.0.1:%d/" % self.port
        self.messages = generate_smach_msgs(home / "msgs")
        self.master: subprocess.Popen | None = None

    def ros_env(self) -> dict[str, str]:
        """What every node of this master needs: where the master is, where its logs go."""
        env = {key: value for key, value in os.environ.items() if not key.startswith("ROS")}
        env.update(ROS_MASTER_URI=self.master_uri, ROS_HOSTNAME="127.0.0.1", ROS_HOME=str(self.home / "ros"),
                   ROS_LOG_DIR=str(self.home / "ros" / "log"), PYTHONUNBUFFERED="1")
        env.pop("PYTHONPATH", None)
        return env

    def robot_env(self) -> dict[str, str]:
        """A robot's: the project, the original SMACH and smach_ros, smach_msgs' classes on its path;
        smach_ros's package where ``roslib.load_manifest`` looks."""
        env = self.ros_env()
        env["PYTHONPATH"] = os.pathsep.join(
            [str(ROOT), str(NOETIC / "smach" / "src"), str(NOETIC / "smach_ros" / "src"), str(self.messages)])
        env["ROS_PACKAGE_PATH"] = str(NOETIC / "smach_ros")
        return env

    def start(self) -> Ros1:
        self.master = subprocess.Popen(["rosmaster", "--core", "-p", str(self.port)], env=self.ros_env(),
                                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        wait_for(self._master_answers, 20, what="rosmaster to answer on port %d" % self.port)
        return self

    def _master_answers(self) -> bool:
        import xmlrpc.client

        if self.master.poll() is not None:
            raise RuntimeError("rosmaster exited with %d" % self.master.returncode)
        try:
            return xmlrpc.client.ServerProxy(self.master_uri).getPid("/test")[0] == 1
        except OSError:
            return False

    def robot(self, script: str, *args: str) -> Robot:
        """``python tests/robots/SCRIPT ARGS...`` as a node of this master."""
        return Robot([sys.executable, "-c", _WITH_DEBIAN_PACKAGES_LAST, str(ROBOTS / script), *args],
                     self.robot_env(), self.home)

    def rostopic(self, *args: str) -> subprocess.Popen:
        """The real ``rostopic ARGS...`` against this master, started (its output piped, as text)."""
        return subprocess.Popen(["rostopic", *args], env=self.ros_env(), stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True)

    def stop(self) -> None:
        if self.master is not None and self.master.poll() is None:
            self.master.terminate()
            try:
                self.master.wait(10)
            except subprocess.TimeoutExpired:
                self.master.kill()
                self.master.wait()


class Robot:
    """A robot's process, in a group of its own: ``url``, the dashboard's address it printed first
    (``dashboard: URL``); ``output``, all it printed (both streams, in order) so far."""

    def __init__(self, argv: list[str], env: dict[str, str], cwd: Path) -> None:
        self.proc = subprocess.Popen(argv, env=env, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True, start_new_session=True)
        self._lines: list[str] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        try:
            self.url = wait_for(self._printed_url, 60, interval=0.05, what=lambda: "the robot to print its URL:\n"
                                + self.output)
        except (RuntimeError, TimeoutError):
            self.stop()
            raise

    def _read(self) -> None:
        for line in self.proc.stdout:
            self._lines.append(line)

    @property
    def output(self) -> str:
        return "".join(self._lines)

    def _printed_url(self) -> str | None:
        found = re.search(r"^dashboard: (http://\S+)$", self.output, re.M)
        if found is None and self.proc.poll() is not None:
            raise RuntimeError("the robot exited with %d before printing its URL:\n%s" % (self.proc.returncode,
                                                                                           self.output))
        return found.group(1) if found else None

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
