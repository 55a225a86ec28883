"""Robots nobody may change, seen live: two real ROS 1 robots (tests/robots/smach_ros_loop.py: the
original SMACH with smach_ros's own IntrospectionServer on rospy, a real rosmaster) followed by a real
``fsmscope ros1`` process, which has no rospy: it speaks to the master and the robots itself
(fsmscope/ros1/). Each robot's stop topic is its own (``--stop-topic MACHINE=TOPIC``), so a
preempt of one leaves the other running."""

from __future__ import annotations

import re
import signal

from fsm.logfiles.log_reader import read_events
from fsmscope.server.testing.polling import wait_for

from fleet_support import stop
from recording_support import cli
from ros1_support import READY, Robot, rospy_lines

def _moved(events: list[dict]) -> list[dict]:
    return [e for e in events if e["kind"] == "transition" and e["path"] == "/SM_ROOT/RUN/WORK"]


def test_every_robots_machine_is_shown_running_with_its_active_states(live):
    for name in ("r1", "r2"):
        wait_for(lambda: live.machines()[name]["running"], 10, interval=0.1, what="%s running" % name)
        status = live.get("/api/machines/%s/status" % name).json()
        assert status["containers"]["/SM_ROOT/RUN/WORK"]["active"][0] in ("MOVE", "SCAN")
        assert status["containers"]["/SM_ROOT/RUN"]["active"] == ["MONITOR", "WORK"]


def test_a_transition_on_the_robot_appears_with_its_outcome_from_the_robots_own_lines(live):
    seen = len(_moved(live.events("r1")))
    wait_for(lambda: len(_moved(live.events("r1"))) >= seen + 2, 10, interval=0.1, what="two more transitions")
    steps = {(e["from"], e["outcome"], e["to"]) for e in _moved(live.events("r1"))}
    assert steps <= {("MOVE", "arrived", "SCAN"), ("SCAN", "scanned", "MOVE")}


def test_a_control_smach_ros_does_not_take_is_refused_saying_what_would_take_it(live):
    answer = live.post("/api/machines/r1/pause", {})
    assert answer.status_code == 409
    assert "fsmscope's IntrospectionServer in the robot's process" in answer.json()["detail"]
    assert "pause" in live.machines()["r1"]["cannot"]


def test_set_initial_state_makes_the_robots_next_run_start_there_after_a_preempt_ends_this_one(live, robots):
    robot: Robot = robots["r1"]
    answer = live.post("/api/machines/r1/initial-state", {"path": "/SM_ROOT/RUN/WORK", "states": ["SCAN"],
                                                           "userdata": {"rounds": 0}})
    assert answer.status_code in (200, 202), answer.text
    runs_before = robot.output.count("outcome: ")
    answer = live.post("/api/machines/r1/preempt", {"reason": "test"})
    assert answer.status_code == 202, answer.text
    wait_for(lambda: robot.output.count("outcome: ") > runs_before, 15, interval=0.1,
             what=lambda: "r1's run to end:\n" + robot.output[-2000:])
    assert robot.output.split("outcome: ")[runs_before + 1].startswith("stopped")
    wait_for(lambda: re.search(r"outcome: stopped\n(.*\n)*.*starting in initial state 'SCAN'", robot.output), 15,
             interval=0.1, what=lambda: "r1's next run to start at SCAN:\n" + robot.output[-2000:])
    ended = [e for e in live.events("r1", "terminate") if e["path"] == "/SM_ROOT/RUN"]
    assert ended and ended[-1]["outcome"] == "stopped"
    assert live.machines()["r2"]["running"]  # its own stop topic: untouched


def test_the_controls_asked_are_in_the_machines_audit(live):
    controls = [(e["action"], e["result"]) for e in live.events("r1", "control")]
    assert ("pause", "accepted") not in controls and ("preempt", "accepted") in controls
    assert ("initial-state", "accepted") in controls


def test_a_robot_killed_shows_disconnected_and_comes_back_when_started_again(ros, live, robots):
    robots["r2"].proc.send_signal(signal.SIGKILL)
    robots["r2"].proc.wait(10)
    wait_for(lambda: live.machines()["r2"]["connected"] is False, 20, interval=0.1, what="r2 disconnected")
    assert live.machines()["r1"]["connected"] is True
    robots["r2"] = ros.robot("smach_ros_loop.py", "robot2", "/r2", "/r2/sm_stop", ready=READY)
    wait_for(lambda: live.machines()["r2"]["connected"] is True, 20, interval=0.1, what="r2 back")
    wait_for(lambda: live.machines()["r2"]["running"], 20, interval=0.1, what="r2's new run")


def test_the_recording_replays_the_robots_transitions_as_its_console_printed_them(live, robots):
    stop(live.proc)
    printed = cli("replay", str(live.recording))
    assert printed.returncode == 1, printed.stderr  # the recording ends while the robots run: unfinished
    said = re.compile(r"^State machine (transitioning|terminating) ")
    replayed = [m.group(1) for m in re.finditer(r" r1:\S+ \[  INFO \] : (.*)$", printed.stdout, re.M) if said.match(m.group(1))]
    console = [msg for _, msg in rospy_lines(robots["r1"].output) if said.match(msg)]
    assert len(replayed) >= 4, printed.stdout[-3000:]
    assert "\n".join(replayed) in "\n".join(console)


def test_a_machine_joined_while_it_ran_starts_each_container_at_one_of_its_own_states(live):
    events = [e for e in read_events(live.recording) if e["machine"] == "r1"]
    children = {}
    for event in events:
        if event["kind"] == "structure":
            stack = [event["root"]]
            while stack:
                node = stack.pop()
                children[node["path"]] = {child["label"] for child in node.get("children", [])}
                stack.extend(node.get("children", []))
    starts = [(e["path"], e["initial"]) for e in events if e["kind"] == "start"]
    assert starts and all(set(initial) <= children[path] for path, initial in starts), starts
