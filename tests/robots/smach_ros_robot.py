"""A ROS 1 robot whose code nobody changed for fsmscope: the original SMACH with smach_ros's own
IntrospectionServer on rospy, one server per machine. Run by tests/ros1/test_ros1_bags.py against a
real rosmaster while the real ``rosbag record -a`` records it, as ``smach_ros_robot.py TRUTH
MACHINE...``: each machine runs once, one after another, and what really ran is recorded in TRUTH
by fsmscope's watcher attached to the original machine (``fsm.attach``), the ground truth a bag's
import is compared with. It prints ``ready`` once every server has a subscriber (the recorder),
``outcome: MACHINE OUTCOME`` after each run and ``done`` at the end.

pick      GRASP retries itself once ('retry' -> GRASP), then PAR: a Concurrence of MONITOR (smach_ros's
          MonitorState on /pick_stop, never published: it is preempted) and TASK (a StateMachine
          STEP1 -> STEP2 -> 'finished'), whose end ends PAR 'done'; PLACE -> root 'done'.
jam       PICK: a Concurrence of ARM ('reached') and GRIPPER (a StateMachine whose CLOSE jams:
          'jammed'); no outcome_map entry holds, so PICK ends 'failed' (its default), the root 'aborted'.
count     COUNT: an Iterator over [10, 20, 30] of BODY (a StateMachine whose ADD adds the item to
          'total': 0 -> 10 -> 30 -> 60, 'continue' loops), exhausted 'counted'; root 'counted'.
stop      WAIT: a Concurrence of LEFT and RIGHT (each waits until preempted); the robot preempts the
          machine 1 s in: both return 'preempted', WAIT services the preempt, the root ends 'preempted'.
"""
import sys
import threading
import time

import fsm
import rospy
import smach
import smach_ros
from std_msgs.msg import Empty

PAUSE = 0.3  # seconds a step works: a status of each step reaches the recorder before the next


class Step(smach.State):
    """Works PAUSE seconds, then returns its outcomes one after another (the last one again and again)."""

    def __init__(self, outcomes, returns=None, **keys):
        smach.State.__init__(self, outcomes, **keys)
        self.returns = list(returns or outcomes[:1])

    def execute(self, ud):
        rospy.sleep(PAUSE)
        return self.returns.pop(0) if len(self.returns) > 1 else self.returns[0]


class Waiting(smach.State):
    def __init__(self):
        smach.State.__init__(self, ["waited", "preempted"])

    def execute(self, ud):
        while not self.preempt_requested():
            rospy.sleep(0.02)
        self.service_preempt()
        return "preempted"


class Add(smach.State):
    def __init__(self):
        smach.State.__init__(self, ["added"], input_keys=["item", "total"], output_keys=["total"])

    def execute(self, ud):
        rospy.sleep(PAUSE)
        ud.total = ud.total + ud.item
        return "added"


def pick():
    task = smach.StateMachine(outcomes=["finished", "failed"])
    with task:
        smach.StateMachine.add("STEP1", Step(["ok", "failed"]), {"ok": "STEP2"})
        smach.StateMachine.add("STEP2", Step(["ok", "failed"]), {"ok": "finished"})
    par = smach.Concurrence(outcomes=["done", "failed"], default_outcome="failed",
                            outcome_map={"done": {"TASK": "finished"}, "failed": {"MONITOR": "invalid"}},
                            child_termination_cb=lambda outcomes: outcomes.get("TASK") is not None)
    with par:
        smach.Concurrence.add("MONITOR", smach_ros.MonitorState("/pick_stop", Empty, lambda ud, msg: False))
        smach.Concurrence.add("TASK", task)
    root = smach.StateMachine(outcomes=["done", "aborted"])
    root.userdata.tries = 0
    with root:
        smach.StateMachine.add("GRASP", Step(["retry", "grasped", "lost"], ["retry", "grasped"]),
                               {"retry": "GRASP", "grasped": "PAR", "lost": "aborted"})
        smach.StateMachine.add("PAR", par, {"done": "PLACE", "failed": "aborted"})
        smach.StateMachine.add("PLACE", Step(["placed"]), {"placed": "done"})
    return root


def jam():
    gripper = smach.StateMachine(outcomes=["closed", "jammed"])
    with gripper:
        smach.StateMachine.add("CLOSE", Step(["closed", "jammed"], ["jammed"]))
    pick_ = smach.Concurrence(outcomes=["done", "failed"], default_outcome="failed",
                              outcome_map={"done": {"ARM": "reached", "GRIPPER": "closed"}})
    with pick_:
        smach.Concurrence.add("ARM", Step(["reached"]))
        smach.Concurrence.add("GRIPPER", gripper)
    root = smach.StateMachine(outcomes=["done", "aborted"])
    with root:
        smach.StateMachine.add("PICK", pick_, {"done": "done", "failed": "aborted"})
    return root


def count():
    body = smach.StateMachine(outcomes=["continue"], input_keys=["item", "total"], output_keys=["total"])
    with body:
        smach.StateMachine.add("ADD", Add(), {"added": "continue"})
    it = smach.Iterator(outcomes=["counted"], input_keys=["total"], output_keys=["total"], it=[10, 20, 30],
                        it_label="item", exhausted_outcome="counted")
    with it:
        smach.Iterator.set_contained_state("BODY", body, loop_outcomes=["continue"])
    root = smach.StateMachine(outcomes=["counted"])
    root.userdata.total = 0
    with root:
        smach.StateMachine.add("COUNT", it, {"counted": "counted"})
    return root


def stop():
    wait = smach.Concurrence(outcomes=["waited", "preempted"], default_outcome="waited")
    with wait:
        smach.Concurrence.add("LEFT", Waiting())
        smach.Concurrence.add("RIGHT", Waiting())
    root = smach.StateMachine(outcomes=["done", "preempted"])
    with root:
        smach.StateMachine.add("WAIT", wait, {"waited": "done"})
    root.register_start_cb(lambda ud, states: threading.Timer(1.0, root.request_preempt).start())
    return root


MACHINES = {"pick": pick, "jam": jam, "count": count, "stop": stop}


def subscribed(server):
    return all(proxy._status_pub.get_num_connections() and proxy._structure_pub.get_num_connections()
               for proxy in server._proxies)


rospy.init_node("smach_robot")
recorder = fsm.Recorder(sys.argv[1], new=True)
machines = [(name, MACHINES[name]()) for name in sys.argv[2:]]
servers = []
for name, machine in machines:
    fsm.attach(machine, recorder, name=name, path="/SM_ROOT")
    server = smach_ros.IntrospectionServer(name, machine, "/SM_ROOT")
    server.start()
    servers.append(server)
while not all(map(subscribed, servers)) and not rospy.is_shutdown():
    rospy.sleep(0.1)
rospy.sleep(1.0)  # the recorder subscribes to /rosout too, and hears the structures' first heartbeat
print("ready", flush=True)
for name, machine in machines:
    print("outcome: %s %s" % (name, machine.execute()), flush=True)
    rospy.sleep(2.5)  # every container's heartbeat tells its userdata after the run
for server in servers:
    server.stop()
recorder.close()
print("done", flush=True)
time.sleep(0.5)
