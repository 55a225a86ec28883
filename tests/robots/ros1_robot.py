"""A ROS 1 robot as its people write it: the original SMACH with smach_ros on rospy, and fsmscope's
IntrospectionServer where smach_ros's stood. Run by tests/ros1/ against a real rosmaster
(tests/ros1_support.py) as ``ros1_robot.py RECORDING``: it prints the dashboard's URL, records the
run, and spins until it is stopped, as a robot's node does (the machine runs in a thread of its own,
smach_ros's preempt handler preempting it on shutdown).

ROBOT
  PATROL (Concurrence: whichever child ends first ends it)
    MONITOR_STOP  smach_ros.MonitorState on /sm_stop (std_msgs/Empty): a message there -> 'invalid'
    WORK          MOVE -> SCAN -> MOVE ...; SCAN fails its first try of every round, RETRY sends it back
                  (up to MAX_TRIES); MOVE counts the rounds in the userdata
  PATROL 'stopped' (MONITOR_STOP 'invalid') -> DOCK -> 'stopped'
"""
import os
import sys
import threading

import fsm
import rospy
import smach
import smach_ros
from fsmscope import IntrospectionServer
from std_msgs.msg import Empty

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # run with runpy: its folder is not on the path
from rospy_states import Timed  # noqa: E402

MAX_TRIES = 3


class Move(Timed):
    def __init__(self):
        Timed.__init__(self, 0.4, ["arrived"], input_keys=["rounds"], output_keys=["rounds", "tries"])

    def done(self, ud):
        ud.rounds = ud.rounds + 1
        ud.tries = 0
        return "arrived"


class Scan(Timed):
    def __init__(self):
        Timed.__init__(self, 0.3, ["scanned", "blurred"], input_keys=["tries"])

    def done(self, ud):
        return "blurred" if ud.tries == 0 else "scanned"


class Retry(smach.State):
    def __init__(self):
        smach.State.__init__(self, ["again", "give_up"], input_keys=["tries"], output_keys=["tries"])

    def execute(self, ud):
        ud.tries = ud.tries + 1
        return "again" if ud.tries < MAX_TRIES else "give_up"


class Dock(Timed):
    def __init__(self):
        Timed.__init__(self, 0.1, ["docked"])

    def done(self, ud):
        return "docked"


def build():
    work = smach.StateMachine(outcomes=["failed", "preempted"], input_keys=["rounds"], output_keys=["rounds"])
    work.userdata.tries = 0
    with work:
        smach.StateMachine.add("MOVE", Move(), {"arrived": "SCAN"})
        smach.StateMachine.add("SCAN", Scan(), {"scanned": "MOVE", "blurred": "RETRY"})
        smach.StateMachine.add("RETRY", Retry(), {"again": "SCAN", "give_up": "failed"})

    patrol = smach.Concurrence(outcomes=["stopped", "failed", "preempted"], default_outcome="preempted",
                               input_keys=["rounds"], output_keys=["rounds"],
                               child_termination_cb=lambda outcomes: True,
                               outcome_map={"stopped": {"MONITOR_STOP": "invalid"}, "failed": {"WORK": "failed"}})
    with patrol:
        smach.Concurrence.add("MONITOR_STOP", smach_ros.MonitorState("/sm_stop", Empty, lambda ud, msg: False))
        smach.Concurrence.add("WORK", work)

    robot = smach.StateMachine(outcomes=["stopped", "failed", "preempted"])
    robot.userdata.rounds = 0
    with robot:
        smach.StateMachine.add("PATROL", patrol, {"stopped": "DOCK"})
        smach.StateMachine.add("DOCK", Dock(), {"docked": "stopped"})
    return robot


def run(machine):
    print("outcome: %s" % machine.execute(), flush=True)


rospy.init_node("fsmscope_robot")
sm = build()
sis = IntrospectionServer("robot", sm, "/SM_ROOT")
sis.start()
fsm.attach(sm, fsm.Recorder(sys.argv[1], new=True))
print("dashboard: %s" % sis.url, flush=True)
smach_ros.set_preempt_handler(sm)  # a shutdown (Ctrl-C) preempts the machine, and waits for it to end
runner = threading.Thread(target=run, args=(sm,))
runner.start()
rospy.spin()
runner.join()
sis.stop()
