"""smach_ros's own IntrospectionServer, publishing for real: a private rosmaster
(fsmscope/server/testing/ros1.py, as the ROS 1 tests start one), a subscriber to the server's status
topic in another process (the real ``rostopic hz``, subscribed as smach_viewer is), and this process
as a node of that master (``rospy.init_node``, anonymous, signals left to the bench), where a machine
of the original smach is introspected as a user does: ``smach_ros.IntrospectionServer("bench", sm,
"/SM_ROOT").start()``. Used by bench/original_smach.py, in its own process and in the processes it
counts under callgrind (``Master.env`` is what they run in)."""

from __future__ import annotations

import collections
import os
import shutil
import sys
import tempfile
import threading
import time
from pathlib import Path
from typing import Any

from fsmscope.server.testing.ros1 import DEBIAN_PACKAGES, Ros1

TOPIC = "/bench/smach/container_status"  # the status topic of IntrospectionServer("bench", ...)
CONNECTED_TIMEOUT = 120.0  # s the subscriber is given to connect to a node's publisher (minutes under callgrind)


class Master:
    """A private rosmaster and ``rostopic hz`` subscribed to ``TOPIC``, until ``close``; ``env``: the
    environment of a node of this master that runs the original smach with smach_ros."""

    def __init__(self) -> None:
        self.home = Path(tempfile.mkdtemp(prefix="fsmscope-bench-ros1-"))
        self.ros = Ros1(self.home)
        self.subscriber = None
        try:
            self.ros.start()
            self.env = self.ros.robot_env()
            self.subscriber = self.ros.rostopic("hz", TOPIC, env=self.env)
        except BaseException:
            self.close()
            raise
        self.printed: collections.deque[str] = collections.deque(maxlen=20)
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        for line in self.subscriber.stdout:  # read as it prints, so that it never waits on a full pipe
            self.printed.append(line)

    def close(self) -> None:
        if self.subscriber is not None and self.subscriber.poll() is None:
            self.subscriber.terminate()
            try:
                self.subscriber.wait(10)
            except Exception:
                self.subscriber.kill()
                self.subscriber.wait()
        self.ros.stop()
        shutil.rmtree(self.home, ignore_errors=True)


class Node:
    """This process as a node of the master ``env`` names (``Master.env``): rospy and smach_ros
    imported, the original smach's loggers and shutdown check left as they were (smach_ros's import
    sets them to rospy's; every case of the bench runs with the same core), ``rospy.init_node`` done."""

    def __init__(self, env: dict[str, str]) -> None:
        os.environ.update({key: value for key, value in env.items() if key != "PYTHONPATH"})
        for folder in env.get("PYTHONPATH", "").split(os.pathsep) + [DEBIAN_PACKAGES]:
            if folder and folder not in sys.path:
                sys.path.append(folder)
        import smach
        loggers = (smach.loginfo, smach.logwarn, smach.logdebug, smach.logerr)
        shutdown_check = smach.is_shutdown
        import rospy
        import smach_ros
        from smach_msgs.msg import SmachContainerStatus
        smach.set_loggers(*loggers)
        smach.set_shutdown_check(shutdown_check)
        rospy.init_node("bench", anonymous=True, disable_signals=True)
        self.rospy = rospy
        self.smach_ros = smach_ros
        self.status = rospy.Publisher(TOPIC, SmachContainerStatus, queue_size=1)  # the same topic: its connections

    def introspect(self, machine: Any) -> Introspected:
        """smach_ros's IntrospectionServer started on ``machine``, once the subscriber is connected to its status."""
        sis = self.smach_ros.IntrospectionServer("bench", machine, "/SM_ROOT")
        sis.start()
        deadline = time.monotonic() + CONNECTED_TIMEOUT
        while self.status.get_num_connections() < 1:
            if time.monotonic() > deadline:
                raise TimeoutError("no subscriber connected to %s in %.0f s" % (TOPIC, CONNECTED_TIMEOUT))
            time.sleep(0.01)
        return Introspected(sis)

    def close(self) -> None:
        self.rospy.signal_shutdown("the bench is done")


class Introspected:
    """A started IntrospectionServer, to stop (its heartbeat threads) when the machine's run is measured."""

    def __init__(self, sis: Any) -> None:
        self.sis = sis

    def close(self) -> None:
        self.sis.stop()
