"""Bags of a real robot, read as what really ran: the original SMACH with smach_ros's own
IntrospectionServer on rospy (tests/robots/smach_ros_robot.py: a GRASP that retries itself, a
Concurrence whose MONITOR is preempted when its TASK finishes, a gripper that jams, an Iterator of
three iterations), recorded by the real ``rosbag record -a`` against a real rosmaster. What really ran
is what fsmscope's watcher, attached to the original machine, recorded in the robot: a bag's import
must print the same SMACH lines (its transcript) and end in the same userdata; from /rosout's lines
it can. The same messages written as ROS 2 bags read the same; without /rosout nothing is invented."""

from __future__ import annotations

import sqlite3
from dataclasses import dataclass
from pathlib import Path

import pytest
from fsm.logfiles.log_reader import read_events
from fsm.logfiles.transcript import messages
from fsm.observation.status import rebuild

from fsmscope.interop import bag_reader, smach_events
from fsmscope.interop.testing import rewrite
from recording_support import cli

MACHINES = ("pick", "jam", "count", "stop")


@dataclass
class Recorded:
    bag: Path  # what rosbag recorded
    truth: list[dict]  # what the watcher in the robot recorded
    folder: Path


@pytest.fixture(scope="module")
def recorded(ros) -> Recorded:
    bag, truth = ros.home / "robot.bag", ros.home / "truth.jsonl"
    printed = ros.recorded(bag, "smach_ros_robot.py", str(truth), *MACHINES)
    assert "outcome: jam aborted" in printed and "outcome: count counted" in printed, printed
    return Recorded(bag, list(read_events(str(truth))), ros.home)


def lines(events) -> dict[str, list[tuple[str, str]]]:
    """Each machine's SMACH lines (level, text), as ``fsmscope replay`` prints them; no debug lines:
    rospy sends INFO and above to /rosout."""
    out: dict[str, list[tuple[str, str]]] = {}
    for line in messages(events):
        if line.level != "debug":
            out.setdefault(line.machine, []).append((line.level, line.msg))
    return out


def imported(bag: Path) -> list[dict]:
    return list(smach_events.events(bag_reader.read_bag(str(bag))))


def userdata(events) -> dict[tuple[str, str], dict]:
    return {(machine, path): c["userdata"] for machine, status in rebuild(events).items()
            for path, c in status.to_dict()["containers"].items()}


def test_the_bag_prints_the_lines_of_what_really_ran(recorded):
    bag = lines(imported(recorded.bag))
    truth = lines(recorded.truth)
    assert set(truth) == set(MACHINES)
    for machine in MACHINES:
        assert bag[machine] == truth[machine], machine


def test_the_retry_of_grasp_to_itself_is_a_transition(recorded):
    assert ("info", "State machine transitioning 'GRASP':'retry'-->'GRASP'") in lines(imported(recorded.bag))["pick"]


def test_the_preempted_monitor_and_the_finished_task_are_told_with_their_outcomes(recorded):
    pick = lines(imported(recorded.bag))["pick"]
    assert ("info", "Concurrent state 'MONITOR' returned outcome 'preempted' on termination.") in pick
    assert ("info", "State machine terminating 'STEP2':'ok':'finished'") in pick
    assert ("info", "Concurrent Outcomes: {'MONITOR': 'preempted', 'TASK': 'finished'}") in pick
    assert pick[-1] == ("info", "State machine terminating 'PLACE':'placed':'done'")


def test_the_jammed_gripper_aborts_the_root_and_replay_says_so(recorded):
    jam = lines(imported(recorded.bag))["jam"]
    assert ("info", "Concurrent state 'GRIPPER' returned outcome 'jammed' on termination.") in jam
    assert jam[-2:] == [("info", "Concurrent Outcomes: {'ARM': 'reached', 'GRIPPER': 'jammed'}"),
                        ("info", "State machine terminating 'PICK':'failed':'aborted'")]
    done = cli("replay", recorded.bag, "--no-transcript")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "machine jam: finished with outcome 'aborted'" in done.stdout


def test_the_iterator_is_one_its_iterations_are_transitions_and_body_ends_with_its_last_userdata(recorded):
    events = imported(recorded.bag)
    root = next(e for e in events if e["kind"] == "structure" and e["machine"] == "count")["root"]
    assert root["children"][0]["type"] == "Iterator"
    looped = [(e["from"], e["outcome"], e["to"]) for e in events
              if e["machine"] == "count" and e["kind"] == "transition" and e["path"] == "/SM_ROOT/COUNT"]
    assert looped == [("BODY", "continue", "BODY")] * 3
    assert userdata(events)["count", "/SM_ROOT/COUNT/BODY"] == {"item": 30, "total": 60}
    assert userdata(events) == userdata(recorded.truth)


@pytest.mark.parametrize("layout", ["ros2-sqlite3", "ros2-mcap"])
def test_the_same_messages_in_a_ros2_bag_print_the_same_lines(recorded, layout, tmp_path):
    bag = rewrite(recorded.bag, tmp_path / layout, layout)
    if layout == "ros2-sqlite3":  # rosbag2 marks the definitions it did not have 'unknown'
        for db in bag.glob("*.db3"):
            with sqlite3.connect(db) as con:
                con.execute("UPDATE message_definitions SET encoding = 'unknown', encoded_message_definition = ''")
    assert lines(imported(bag)) == lines(recorded.truth)
    done = cli("replay", bag, "--no-transcript")
    assert done.returncode == 0, done.stdout + done.stderr


def test_without_rosout_no_outcome_is_invented_and_an_untold_end_exits_1(recorded, tmp_path):
    bag = rewrite(recorded.bag, tmp_path / "statuses.bag", "ros1", rosout=False)
    told, truth = lines(imported(bag)), lines(recorded.truth)
    for machine in MACHINES:
        said = {text for _, text in truth[machine]}
        wrong = [text for _, text in told[machine] if text not in said and "'?'" not in text and "{" not in text]
        assert wrong == [], machine
    assert ("info", "Concurrent state 'GRIPPER' returned outcome '?' on termination.") in told["jam"]
    assert told["jam"][-1] == ("info", "State machine terminating 'PICK':'?':'?'")
    done = cli("replay", bag, "--no-transcript")
    assert done.returncode == 1, done.stdout + done.stderr
    assert "machine jam: the end of its last run is not in the bag" in done.stderr


def test_a_recorder_that_joined_late_tells_only_transitions_the_machine_has(recorded, tmp_path):
    grasped = next(e["t"] for e in recorded.truth if e["kind"] == "transition" and e.get("to") == "PAR")
    bag = rewrite(recorded.bag, tmp_path / "late.bag", "ros1", since=grasped + 0.1)
    events = [e for e in imported(bag) if e["machine"] == "pick"]
    edges = {(e["path"], e["from"], e["outcome"], e["to"]) for e in recorded.truth
             if e["kind"] == "transition" and e["machine"] == "pick"}
    told = [(e["path"], e["from"], e["outcome"], e["to"]) for e in events if e["kind"] == "transition"]
    assert told and set(told) <= edges
    start = next(e for e in events if e["kind"] == "start")
    assert (start["path"], start["active"]) == ("/SM_ROOT", ["PAR"])
    ends = [e["outcome"] for e in events if e["kind"] == "terminate" and e["path"] == "/SM_ROOT"]
    assert ends == ["done"]


def test_a_recorder_stopped_right_after_the_run_knows_its_end_from_rosout(recorded, tmp_path):
    ended = next(e["t"] for e in recorded.truth if e["kind"] == "terminate" and e["machine"] == "pick"
                 and e["path"] == "/SM_ROOT")
    bag = rewrite(recorded.bag, tmp_path / "stopped.bag", "ros1", until=ended + 0.1)
    done = cli("replay", bag, "--no-transcript")
    assert "machine pick: finished with outcome 'done'" in done.stdout, done.stdout + done.stderr


def test_a_concurrence_that_services_a_preempt_ends_preempted(recorded):
    stop = lines(imported(recorded.bag))["stop"]
    assert stop[-2:] == [("info", "Concurrence serviced preempt."),
                         ("info", "State machine terminating 'WAIT':'preempted':'preempted'")]
    assert not any(text.startswith("Concurrent Outcomes") for _, text in stop)
