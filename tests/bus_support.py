"""Helpers shared by the bus, actionlib and smach_ros-state tests."""

import time

from fsm.ros.actionlib import SimpleActionServer
from fsm.ros.bus import Bus


def serve(bus: Bus, servers: list, execute_cb, name: str = "act", **kwargs) -> SimpleActionServer:
    server = SimpleActionServer(name, execute_cb, bus=bus, **kwargs)
    servers.append(server)
    return server


def until_preempted(server: SimpleActionServer, result=None):
    """An execute_cb body that publishes feedback until preempted, then reports the preemption."""
    def execute(goal):
        n = 0
        while not server.is_preempt_requested():
            server.publish_feedback({"n": n})
            n += 1
            time.sleep(0.005)
        server.set_preempted(result if result is not None else {"stopped": goal}, "stopped")
    return execute
