"""A nested sub-machine, then a Concurrence of a long action beside a MonitorState on 'sm_stop'.

A message on the topic 'sm_stop' (any message) makes the monitor return 'invalid'; the
Concurrence then preempts the action and the machine ends 'preempted'. Run standalone, the
script publishes on 'sm_stop' itself ``--stop-after`` seconds after the Concurrence starts
(default 3; 0 never: then only someone else, such as the dashboard, can stop it, and
otherwise the action succeeds after ``--action-seconds``).

Time is scaled by ``--time-scale`` or the FSMSCOPE_TIME_SCALE environment variable (1.0:
real seconds; the tests use 0.01).
"""

import argparse
import os
import threading
import time

import fsm as smach
from fsm.ros.actionlib import SimpleActionServer
from fsm.ros.bus import get_bus

try:
    MonitorState = smach.MonitorState
    SimpleActionState = smach.SimpleActionState
except AttributeError:
    from fsm.ros.monitor_state import MonitorState
    from fsm.ros.simple_action_state import SimpleActionState

STOP_TOPIC = "sm_stop"


def time_scale(default: float = 1.0) -> float:
    return float(os.environ.get("FSMSCOPE_TIME_SCALE", default))


class Step(smach.State):
    """Logs, waits ``seconds`` (already scaled), counts in userdata, returns 'done'."""

    def __init__(self, seconds: float) -> None:
        smach.State.__init__(self, outcomes=["done"], io_keys=["steps"])
        self.seconds = seconds

    def execute(self, userdata):
        smach.loginfo("Preparing, step %d" % (userdata.steps + 1))
        time.sleep(self.seconds)
        userdata.steps = userdata.steps + 1
        return "done"


def start_action_server(scale: float) -> SimpleActionServer:
    """'long_task': works for ``seconds`` (scaled), with feedback each second, until preempted."""
    def work(goal):
        for second in range(1, goal["seconds"] + 1):
            if server.is_preempt_requested():
                server.set_preempted({"worked": second - 1})
                return
            time.sleep(scale)
            server.publish_feedback({"second": second})
        server.set_succeeded({"worked": goal["seconds"]})

    server = SimpleActionServer("long_task", work)
    return server


def build(scale: float, action_seconds: int = 10, stop_after: float = 3.0) -> smach.StateMachine:
    sm = smach.StateMachine(outcomes=["succeeded", "preempted", "aborted"])
    sm.userdata.steps = 0
    with sm:
        sub = smach.StateMachine(outcomes=["ready"], input_keys=["steps"], output_keys=["steps"])
        with sub:
            smach.StateMachine.add("PREPARE", Step(0.2 * scale), transitions={"done": "CHECK"})
            smach.StateMachine.add("CHECK", Step(0.2 * scale), transitions={"done": "ready"})
        smach.StateMachine.add("SUB", sub, transitions={"ready": "WORK"})

        work = smach.Concurrence(
            outcomes=["succeeded", "preempted", "aborted"], default_outcome="aborted",
            outcome_map={"preempted": {"MONITOR": "invalid"},
                         "succeeded": {"ACTION": "succeeded"}},
            child_termination_cb=lambda outcomes: True)  # whoever ends first stops the other
        with work:
            smach.Concurrence.add("ACTION", SimpleActionState("long_task", goal={"seconds": action_seconds}))
            smach.Concurrence.add("MONITOR", MonitorState(STOP_TOPIC, None, lambda ud, msg: False))
        if stop_after > 0:
            work.register_start_cb(lambda ud, initial: _publish_later(stop_after * scale))
        smach.StateMachine.add("WORK", work, transitions={})
    return sm


def _publish_later(delay: float) -> None:
    timer = threading.Timer(delay, get_bus().publish, (STOP_TOPIC, {"reason": "nested_monitor.py stops itself"}))
    timer.daemon = True
    timer.start()


def main(argv: list[str] | None = None) -> str:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--time-scale", type=float, default=time_scale())
    parser.add_argument("--stop-after", type=float, default=3.0,
                        help="publish on 'sm_stop' this many (scaled) seconds after the work starts; 0: never")
    parser.add_argument("--action-seconds", type=int, default=10)
    args = parser.parse_args(argv)
    server = start_action_server(args.time_scale)
    try:
        outcome = build(args.time_scale, args.action_seconds, args.stop_after).execute()
    finally:
        server.shutdown()
    print("nested_monitor finished with outcome: %s" % outcome)
    return outcome


if __name__ == "__main__":
    main()
