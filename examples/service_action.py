"""A ServiceState asks a 'square' service for the square of a random 1..3 and stores it in
userdata; a SimpleActionState sends it as ``seconds_requested`` to a 'count' action server,
which counts with feedback every (scaled) second, checks for preemption, and succeeds.

Time is scaled by ``--time-scale`` or the FSMSCOPE_TIME_SCALE environment variable (1.0:
real seconds; the tests use 0.01). ``--seed`` (or FSMSCOPE_SEED) fixes the random number.
"""

import argparse
import os
import random
import time

import fsm as smach
from fsm.ros.actionlib import SimpleActionServer
from fsm.ros.bus import get_bus

try:
    ServiceState = smach.ServiceState
    SimpleActionState = smach.SimpleActionState
except AttributeError:
    from fsm.ros.service_state import ServiceState
    from fsm.ros.simple_action_state import SimpleActionState


def time_scale(default: float = 1.0) -> float:
    return float(os.environ.get("FSMSCOPE_TIME_SCALE", default))


def start_servers(scale: float) -> tuple:
    """The 'square' service and the 'count' action server, on the default bus."""
    bus = get_bus()
    service = bus.advertise_service("square", lambda request: request["x"] ** 2)

    def count(goal):
        seconds = goal["seconds_requested"]
        for elapsed in range(1, seconds + 1):
            if server.is_preempt_requested():
                server.set_preempted({"seconds_counted": elapsed - 1})
                return
            time.sleep(scale)
            server.publish_feedback({"seconds_elapsed": elapsed, "seconds_remaining": seconds - elapsed})
        server.set_succeeded({"seconds_counted": seconds})

    server = SimpleActionServer("count", count)
    return service, server


def build(rng: random.Random) -> smach.StateMachine:
    sm = smach.StateMachine(outcomes=["succeeded", "aborted", "preempted"])
    with sm:
        smach.StateMachine.add(
            "ASK_SQUARE",
            ServiceState("square", request_cb=lambda ud, request: {"x": rng.randint(1, 3)}, response_key="seconds"),
            transitions={"succeeded": "COUNT"})

        def goal_cb(ud, goal):
            return {"seconds_requested": ud.seconds}

        smach.StateMachine.add(
            "COUNT",
            SimpleActionState("count", goal_cb=goal_cb, input_keys=["seconds"], result_key="count_result"),
            transitions={})
    return sm


def main(argv: list[str] | None = None) -> str:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    env_seed = os.environ.get("FSMSCOPE_SEED")
    parser.add_argument("--seed", type=int, default=int(env_seed) if env_seed else None)
    parser.add_argument("--time-scale", type=float, default=time_scale())
    args = parser.parse_args(argv)
    service, server = start_servers(args.time_scale)
    try:
        sm = build(random.Random(args.seed))
        outcome = sm.execute()
    finally:
        server.shutdown()
        service.shutdown()
    ud = sm.userdata
    print("service_action finished with outcome: %s (seconds=%s, result=%s)"
          % (outcome, ud["seconds"] if "seconds" in ud else None, ud["count_result"] if "count_result" in ud else None))
    return outcome


if __name__ == "__main__":
    main()
