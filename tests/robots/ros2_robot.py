"""A ROS 2 robot as executive_smach's ``ros2`` branch (7fb264e) makes one: its SMACH core and its
smach_ros/introspection.py, both unchanged from ../shared/reference, on rclpy_on_cyclonedds (a
stand-in for rclpy over Cyclone DDS: no ROS 2 here). Run by tests/ros2/ as
``ros2_robot.py DOMAIN_ID [MODE]``, Cyclone configured by ``CYCLONEDDS_URI`` as a robot's is.

MODE ``smach`` (the default): the machine below, its IntrospectionServer ``robot`` (topics
``/robot/smach/container_{structure,status,init}``), runs after run until a message on ``/sm_stop``
(std_msgs/Empty) preempts it, as a MonitorState there would; SMACH logs through the node's logger
(so to ``/rosout``). Prints ``ready`` once serving, ``state: LABEL COUNT`` as each state runs,
``outcome: OUTCOME`` after each run.

  SM_ROOT   A -> SUB -> C -> 'done'        (each state adds 1 to the userdata's count)
    SUB     X -> Y -> 'done'

MODE ``other-type``: publishes ``/robot/smach/container_status`` as std_msgs/String, not smach_msgs.
MODE ``other-layout``: publishes it as a type named smach_msgs/msg/SmachContainerStatus whose layout
is another (ROS 1's ``string local_data``).
MODE ``bad-utf8``: publishes smach_msgs/SmachContainerStatus messages whose ``path`` is no UTF-8 (as a
C++ node can put any bytes in a ROS string), each followed by a good one with ``path`` ``/after``.
"""
import os
import pickle
import sys
import threading
import time
from pathlib import Path

REFERENCE = Path(__file__).resolve().parents[3] / "shared/reference/executive_smach/ros2"
sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(REFERENCE / "smach"))

import rclpy_on_cyclonedds  # noqa: E402

DOMAIN_ID = int(sys.argv[1])
MODE = sys.argv[2] if len(sys.argv) > 2 else "smach"
rclpy_on_cyclonedds.install(REFERENCE / "smach_msgs/msg", DOMAIN_ID)

import importlib.util  # noqa: E402

import rclpy  # noqa: E402  (the stand-in)
import smach  # noqa: E402  (the ros2 branch's core)
from rclpy.node import Node  # noqa: E402
from smach_msgs.msg import SmachContainerStatus  # noqa: E402
from std_msgs.msg import Empty, Header  # noqa: E402


def introspection():
    """smach_ros/introspection.py itself (smach_ros/__init__.py imports actionlib's counterparts too)."""
    spec = importlib.util.spec_from_file_location("introspection", REFERENCE / "smach_ros/smach_ros/introspection.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class Step(smach.State):
    def __init__(self, label):
        smach.State.__init__(self, ["next", "preempted"], input_keys=["count"], output_keys=["count"])
        self.label = label

    def execute(self, ud):
        print(f"state: {self.label} {ud.count}", flush=True)
        end = time.monotonic() + 0.3
        while time.monotonic() < end:
            if self.preempt_requested():
                self.service_preempt()
                return "preempted"
            time.sleep(0.01)
        ud.count = ud.count + 1
        return "next"


def machine():
    root = smach.StateMachine(outcomes=["done", "preempted"])
    root.userdata.count = 0
    with root:
        smach.StateMachine.add("A", Step("A"), transitions={"next": "SUB"})
        sub = smach.StateMachine(outcomes=["done", "preempted"], input_keys=["count"], output_keys=["count"])
        with sub:
            smach.StateMachine.add("X", Step("X"), transitions={"next": "Y"})
            smach.StateMachine.add("Y", Step("Y"), transitions={"next": "done"})
        smach.StateMachine.add("SUB", sub, transitions={"done": "C"})
        smach.StateMachine.add("C", Step("C"), transitions={"next": "done"})
    return root


def run_smach():
    node = Node("robot_main")
    logger = node.get_logger()
    smach.set_loggers(logger.info, logger.warn, logger.debug, logger.error)
    sm = machine()
    sis = introspection().IntrospectionServer("robot", sm, "/SM_ROOT")
    sis.start()
    node.create_subscription(Empty, "/sm_stop", lambda msg: sm.request_preempt(), 10)
    executor = rclpy.executors.SingleThreadedExecutor()
    executor.add_node(node)
    threading.Thread(target=executor.spin, daemon=True).start()
    print("ready", flush=True)
    while True:
        outcome = sm.execute()
        print(f"outcome: {outcome}", flush=True)
        if outcome == "preempted":
            break
    rclpy.shutdown()


def publish_forever(msg_type, publish):
    """``publish(publisher)`` ten times a second, on the status topic, as a node of this process."""
    publisher = Node("impostor").create_publisher(msg_type, "/robot/smach/container_status", 10)
    print("ready", flush=True)
    while True:
        publish(publisher)
        time.sleep(0.1)


def publish_bad_utf8(publisher):
    """A status whose path is no UTF-8, written as serialized bytes (past the Python serializer, which
    writes only UTF-8), then a good one."""
    from cyclonedds._clayer import ddspy_write
    data = bytearray(pickle.dumps({}, 2))
    raw = SmachContainerStatus(header=Header(), path="/\x01\x02", local_data=data).serialize(use_version_2=False)
    ddspy_write(publisher.writer._ref, raw.replace(b"/\x01\x02", b"/\xff\xfe").ljust((len(raw) + 3) & ~3, b"\0"))
    publisher.publish(SmachContainerStatus(header=Header(), path="/after", local_data=data))


if MODE == "smach":
    run_smach()
elif MODE == "other-type":
    String = rclpy_on_cyclonedds._message("std_msgs", "String", "string data\n")
    publish_forever(String, lambda publisher: publisher.publish(String(data="not a status")))
elif MODE == "other-layout":
    Ros1Status = rclpy_on_cyclonedds._message("smach_msgs", "SmachContainerStatus", (
        REFERENCE / "smach_msgs/msg/SmachContainerStatus.msg").read_text().replace("uint8[] local_data", "string local_data"))
    publish_forever(Ros1Status, lambda publisher: publisher.publish(Ros1Status(path="/SM_ROOT", local_data="gAJ9cQAu")))
elif MODE == "bad-utf8":
    publish_forever(SmachContainerStatus, publish_bad_utf8)
else:
    sys.exit(f"unknown mode {MODE!r}")
