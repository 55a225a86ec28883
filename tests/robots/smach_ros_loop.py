"""A ROS 1 robot nobody may change: the original SMACH with smach_ros's own IntrospectionServer on
rospy, and nothing of fsmscope. Run by tests/ros1/ against a real rosmaster as
``smach_ros_loop.py NODE SERVER STOP_TOPIC [ROUNDS]``: node NODE publishes its machine as server
SERVER, runs it again one second after each run ends, prints ``ready`` once it publishes,
``outcome: X`` after each run, and spins until it is stopped.

/SM_ROOT
  RUN (Concurrence: whichever child ends first ends it, the other preempted)
    MONITOR  smach_ros.MonitorState on STOP_TOPIC (std_msgs/Empty): a message there -> 'invalid' -> RUN 'stopped'
    WORK     MOVE -> SCAN -> MOVE ... (each 0.3 s of ROS time); MOVE counts the rounds in the userdata,
             SCAN ends WORK 'done' after ROUNDS rounds (default 1000: until stopped)
  RUN 'stopped' -> DOCK -> 'stopped'; RUN 'done' -> 'done'
"""
import os
import sys
import threading

import rospy
import smach
import smach_ros
from std_msgs.msg import Empty

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # run with runpy: its folder is not on the path
from rospy_states import Timed  # noqa: E402

NODE, SERVER, STOP_TOPIC = sys.argv[1:4]
ROUNDS = int(sys.argv[4]) if len(sys.argv) > 4 else 1000


class Move(Timed):
    def __init__(self):
        Timed.__init__(self, 0.3, ["arrived"], input_keys=["rounds"], output_keys=["rounds"])

    def done(self, ud):
        ud.rounds = ud.rounds + 1
        return "arrived"


class Scan(Timed):
    def __init__(self):
        Timed.__init__(self, 0.3, ["scanned", "finished"], input_keys=["rounds"])

    def done(self, ud):
        return "finished" if ud.rounds >= ROUNDS else "scanned"


class Dock(Timed):
    def __init__(self):
        Timed.__init__(self, 0.3, ["docked"])

    def done(self, ud):
        return "docked"


def build():
    work = smach.StateMachine(outcomes=["done", "preempted"], input_keys=["rounds"], output_keys=["rounds"])
    with work:
        smach.StateMachine.add("MOVE", Move(), {"arrived": "SCAN"})
        smach.StateMachine.add("SCAN", Scan(), {"scanned": "MOVE", "finished": "done"})

    run = smach.Concurrence(outcomes=["stopped", "done", "preempted"], default_outcome="preempted",
                            input_keys=["rounds"], output_keys=["rounds"], child_termination_cb=lambda outcomes: True,
                            outcome_map={"stopped": {"MONITOR": "invalid"}, "done": {"WORK": "done"}})
    with run:
        smach.Concurrence.add("MONITOR", smach_ros.MonitorState(STOP_TOPIC, Empty, lambda ud, msg: False))
        smach.Concurrence.add("WORK", work)

    root = smach.StateMachine(outcomes=["stopped", "done", "preempted"])
    root.userdata.rounds = 0
    with root:
        smach.StateMachine.add("RUN", run, {"stopped": "DOCK", "done": "done"})
        smach.StateMachine.add("DOCK", Dock(), {"docked": "stopped"})
    return root


def runs(machine):
    while not rospy.is_shutdown():
        machine.userdata.rounds = 0
        print("outcome: %s" % machine.execute(), flush=True)
        rospy.sleep(1.0)


rospy.init_node(NODE)
sm = build()
sis = smach_ros.IntrospectionServer(SERVER, sm, "/SM_ROOT")
sis.start()
print("ready", flush=True)
runner = threading.Thread(target=runs, args=(sm,), daemon=True)
runner.start()
rospy.spin()
sis.stop()
