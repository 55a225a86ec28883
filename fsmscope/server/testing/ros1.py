"""A private ROS 1 on this computer: a real ``rosmaster`` on a free port, the environment its nodes
run in (the original SMACH with smach_ros, smach_msgs' classes) and the real ``rostopic``. Shared by
the ROS 1 tests (tests/ros1_support.py) and the bench that measures smach_ros's own
IntrospectionServer publishing (bench/smach_ros_publishing.py).

ROS 1 comes from Debian's packages (``make apt``): rospy, rosmaster and rostopic live in Debian's
Python (/usr/lib/python3/dist-packages). The original SMACH, smach_ros and smach_msgs' .msg files
come from ``../shared/reference`` beside the project root (its README); smach_msgs' Python classes
are generated from them with genpy, as catkin would.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import xmlrpc.client
from pathlib import Path

from fsmscope.server.testing.demo_process import free_port
from fsmscope.server.testing.polling import wait_for

ROOT = Path(__file__).resolve().parents[3]
NOETIC = ROOT.parent / "shared/reference/executive_smach/noetic"
DEBIAN_PACKAGES = "/usr/lib/python3/dist-packages"
GENMSG_PY = "/usr/lib/genpy/genmsg_py.py"
STD_MSGS = "/usr/share/std_msgs/msg"


def missing_ros1() -> str | None:
    """Why a private ROS 1 with the original SMACH cannot run here, or None if it can."""
    if not (NOETIC / "smach_ros" / "package.xml").exists():
        return "the original SMACH and smach_ros are not at %s (a copy of shared/ beside the project root)" % NOETIC
    missing = [tool for tool in ("rosmaster", "rostopic") if shutil.which(tool) is None]
    missing += [path for path in (GENMSG_PY, STD_MSGS) if not os.path.exists(path)]
    if missing:
        return "ROS 1 is not installed (make apt installs Debian's packages): no %s" % ", ".join(missing)
    return None


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
        env["PYTHONPATH"] = os.pathsep.join(self.robot_path())
        env["ROS_PACKAGE_PATH"] = str(NOETIC / "smach_ros")
        return env

    def robot_path(self) -> list[str]:
        """The folders a robot imports from before its Python's own: the project, the original SMACH
        and smach_ros, smach_msgs' classes."""
        return [str(ROOT), str(NOETIC / "smach" / "src"), str(NOETIC / "smach_ros" / "src"), str(self.messages)]

    def start(self) -> Ros1:
        self.master = subprocess.Popen(["rosmaster", "--core", "-p", str(self.port)], env=self.ros_env(),
                                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        wait_for(self._master_answers, 20, what="rosmaster to answer on port %d" % self.port)
        return self

    def _master_answers(self) -> bool:
        if self.master.poll() is not None:
            raise RuntimeError("rosmaster exited with %d" % self.master.returncode)
        try:
            return xmlrpc.client.ServerProxy(self.master_uri).getPid("/test")[0] == 1
        except OSError:
            return False

    def rostopic(self, *args: str, env: dict[str, str] | None = None) -> subprocess.Popen:
        """The real ``rostopic ARGS...`` against this master (in ``env``, by default ``ros_env()``),
        started (its output piped, as text)."""
        return subprocess.Popen(["rostopic", *args], env=env or self.ros_env(), stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, text=True)

    def stop(self) -> None:
        if self.master is not None and self.master.poll() is None:
            self.master.terminate()
            try:
                self.master.wait(10)
            except subprocess.TimeoutExpired:
                self.master.kill()
                self.master.wait()
