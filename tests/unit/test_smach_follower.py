"""smach_ros's messages followed one at a time (fsmscope.interop.smach_events.Follower), as a bag's
reader and a live stream feed them: what a status alone tells, what a SMACH line of /rosout tells,
and what nothing tells (said '?', never guessed)."""

from __future__ import annotations

import base64
import pickle

from bag_support import messages as bag_messages
from recording_support import cli

from fsmscope.interop import bag_reader, smach_events
from fsmscope.interop.bag_reader import Message
from fsmscope.interop.smach_events import Follower
from fsmscope.interop.testing import write_bag

ROOT = "/SM_ROOT"
T0 = 1_700_000_000.0
STEP = "(<smach.user_data.UserData object at 0x7f>, ['X']), {}"  # the info of a transition callback's status


def structure(t: float, path: str, children: list[str], edges: list[tuple[str, str, str]], outcomes: list[str]):
    return Message(T0 + t, "robot", "structure", {
        "path": path, "children": children, "internal_outcomes": [e[0] for e in edges],
        "outcomes_from": [e[1] for e in edges], "outcomes_to": [e[2] for e in edges], "container_outcomes": outcomes},
        "/robot")


def status(t: float, path: str, initial: list[str], active: list[str], info: str = "HEARTBEAT", userdata=None):
    data = base64.b64encode(pickle.dumps(userdata or {}, 2))
    return Message(T0 + t, "robot", "status", {"path": path, "initial_states": initial, "active_states": active,
                                               "info": info, "local_data": data}, "/robot")


def line(t: float, text: str, node: str = "/robot"):
    return Message(T0 + t, "", "log", {"msg": text, "level": 2, "name": node}, node)


PATROL = [("go", "INIT", "WORK"), ("tired", "WORK", "RECOVER"), ("rested", "RECOVER", "done"),
          ("again", "RECOVER", "WORK")]


def told(messages: list[Message]) -> list[tuple]:
    """(kind, path, from, outcome, to) of the run's events, fed one message at a time, then ended."""
    f = Follower("robot", "robot")
    events = [ev for m in messages for ev in f.feed(m)] + f.end()
    return [(ev["kind"], ev["path"], ev.get("from"), ev.get("outcome"), ev.get("to")) for ev in events
            if ev["kind"] in ("start", "transition", "terminate")]


def test_a_recorder_that_joins_late_starts_where_the_machine_is_without_an_edge_it_does_not_have():
    f = Follower("robot", "robot")
    events = [ev for m in (structure(0, ROOT, ["INIT", "WORK", "RECOVER"], PATROL, ["done"]),
                           status(0.1, ROOT, ["INIT"], ["RECOVER"]), status(3, ROOT, ["INIT"], ["RECOVER"]))
              for ev in f.feed(m)]
    start = next(ev for ev in events if ev["kind"] == "start")
    assert (start["initial"], start["active"]) == (["INIT"], ["RECOVER"])
    assert [ev for ev in events if ev["kind"] == "transition"] == []


def test_statuses_before_the_structure_are_told_from_the_structure_once_it_comes():
    assert told([status(0, ROOT, ["INIT"], ["None"]), status(1, ROOT, ["INIT"], ["WORK"], STEP),
                 structure(1.5, ROOT, ["INIT", "WORK", "RECOVER"], PATROL, ["done"]),
                 status(2, ROOT, ["INIT"], ["RECOVER"], STEP)]) == [
        ("start", ROOT, None, None, None), ("transition", ROOT, "INIT", "go", "WORK"),
        ("transition", ROOT, "WORK", "tired", "RECOVER")]


def test_a_structure_that_changes_is_described_again():
    f = Follower("robot", "robot")
    first = [ev for m in (structure(0, ROOT, ["INIT", "WORK"], PATROL[:1], ["done"]),
                          status(2.6, ROOT, ["INIT"], ["None"])) for ev in f.feed(m)]
    again = f.feed(structure(4, ROOT, ["INIT", "WORK", "RECOVER"], PATROL, ["done"]))
    assert [ev["kind"] for ev in first] == ["structure"]
    assert [c["label"] for c in again[0]["root"]["children"]] == ["INIT", "WORK", "RECOVER"]


def test_a_status_of_a_transition_to_the_same_state_is_a_self_transition():
    assert told([structure(0, ROOT, ["INIT", "WORK", "RECOVER"], PATROL + [("retry", "WORK", "WORK")], ["done"]),
                 status(0.6, ROOT, ["INIT"], ["None"]), status(1, ROOT, ["INIT"], ["WORK"], STEP),
                 status(2, ROOT, ["INIT"], ["WORK"], STEP), status(3, ROOT, ["INIT"], ["WORK"])]) == [
        ("start", ROOT, None, None, None), ("transition", ROOT, "INIT", "go", "WORK"),
        ("transition", ROOT, "WORK", "retry", "WORK")]


def test_the_one_place_a_last_state_leads_out_to_is_the_machines_outcome_whatever_it_returned():
    edges = PATROL + [("slept", "RECOVER", "done")]
    assert told([structure(0, ROOT, ["INIT", "WORK", "RECOVER"], edges, ["done"]),
                 status(0.6, ROOT, ["INIT"], ["None"]), status(1, ROOT, ["INIT"], ["RECOVER"]),
                 status(2, ROOT, ["INIT"], ["None"])])[-1] == ("terminate", ROOT, None, "done", None)


def test_a_line_says_the_outcome_a_status_cannot():
    two_ways = PATROL + [("slept", "RECOVER", "WORK")]
    messages = [structure(0, ROOT, ["INIT", "WORK", "RECOVER"], two_ways, ["done"]),
                status(0.6, ROOT, ["INIT"], ["None"]),
                status(1, ROOT, ["INIT"], ["RECOVER"]), status(2, ROOT, ["INIT"], ["WORK"], STEP)]
    assert told(messages)[-1] == ("transition", ROOT, "RECOVER", "?", "WORK")
    messages.insert(3, line(1.99, "State machine transitioning 'RECOVER':'slept'-->'WORK'"))
    assert told(messages)[-1] == ("transition", ROOT, "RECOVER", "slept", "WORK")


def test_a_line_of_another_node_says_nothing_of_this_servers_machine():
    messages = [structure(0, ROOT, ["INIT", "WORK", "RECOVER"], PATROL, ["done"]),
                status(0.6, ROOT, ["INIT"], ["None"]),
                line(1, "State machine starting in initial state 'INIT' with userdata: \n\t[]", node="/other"),
                status(1.5, ROOT, ["INIT"], ["None"])]
    assert [ev["kind"] for ev in smach_events.events(messages)] == ["structure"]


def test_whether_the_last_run_finished_is_known_only_from_its_end():
    f = Follower("robot", "robot")
    for m in (structure(0, ROOT, ["INIT", "WORK", "RECOVER"], PATROL, ["done"]), status(2.6, ROOT, ["INIT"], ["None"])):
        f.feed(m)
    assert f.finished is None
    f.feed(line(3, "State machine starting in initial state 'INIT' with userdata: \n\t[]"))
    assert f.finished is False
    f.feed(line(4, "State machine transitioning 'INIT':'go'-->'WORK'"))
    f.feed(line(5, "State machine transitioning 'WORK':'tired'-->'RECOVER'"))
    ended = f.feed(line(6, "State machine terminating 'RECOVER':'rested':'done'"))
    assert (ended[-1]["kind"], ended[-1]["outcome"]) == ("terminate", "done") and f.finished is True


def test_feeding_a_bags_messages_one_at_a_time_gives_the_bags_events(tmp_path):
    read = list(bag_reader.read_bag(str(write_bag(tmp_path / "run.bag", "ros1", bag_messages()))))
    f = Follower("pick_place", "pick_place")
    fed = [ev for m in read for ev in f.feed(m)] + f.end()
    assert fed == list(smach_events.events(read))


def test_a_bag_whose_run_ends_untold_replays_as_unfinished(tmp_path):
    edges = PATROL + [("slept", "RECOVER", "None")]
    runs = [(t, "/robot/smach/container_%s" % m.kind, m.kind, dict(
        {k: v for k, v in m.fields.items() if k != "local_data"},
        **({"userdata": {}} if m.kind == "status" else {})))
        for t, m in ((m.t, m) for m in (structure(0, ROOT, ["INIT", "WORK", "RECOVER"], edges, ["done", "slept"]),
                                        status(0.6, ROOT, ["INIT"], ["None"]), status(1, ROOT, ["INIT"], ["RECOVER"]),
                                        status(2, ROOT, ["INIT"], ["None"])))]
    done = cli("replay", write_bag(tmp_path / "untold.bag", "ros1", runs), "--no-time")
    assert "State machine terminating 'RECOVER':'?':'?'" in done.stdout
    assert done.returncode == 1 and "machine robot: the end of its last run is not in the bag" in done.stderr


def test_a_machine_that_starts_again_before_its_end_was_told_ends_untold_first():
    assert told([structure(0, ROOT, ["INIT", "WORK", "RECOVER"], PATROL, ["done"]),
                 status(0.6, ROOT, ["INIT"], ["None"]),
                 line(1, "State machine starting in initial state 'INIT' with userdata: \n\t[]"),
                 line(2, "State machine transitioning 'INIT':'go'-->'WORK'"),
                 line(5, "State machine starting in initial state 'INIT' with userdata: \n\t[]")]) == [
        ("start", ROOT, None, None, None), ("transition", ROOT, "INIT", "go", "WORK"),
        ("terminate", ROOT, None, "?", None), ("start", ROOT, None, None, None)]


EDGES_TO_DONE = [("ok", "A", "B"), ("ok", "B", "done"), ("fail", "B", "done")]


def run_of_a_then_b(*end: Message) -> list[Message]:
    """A -> B of a machine whose B has two edges to 'done', with SMACH's lines, then ``end``."""
    return [structure(0, ROOT, ["A", "B"], EDGES_TO_DONE, ["done"]),
            line(0.1, "State machine starting in initial state 'A' with userdata: \n\t[]"),
            status(0.1, ROOT, ["A"], ["A"], info="Initial state"),
            line(0.4, "State machine transitioning 'A':'ok'-->'B'"), status(0.4001, ROOT, ["A"], ["B"], info=STEP),
            *end]


def ends(messages: list[Message]) -> list[tuple]:
    return [(ev["kind"], ev.get("outcome"), ev.get("state_outcome")) for ev in smach_events.events(messages)
            if ev["kind"] in ("start", "terminate")]


def test_a_heartbeat_published_between_smachs_change_of_state_and_its_line_does_not_hide_the_line():
    # SMACH sets the state to none, then logs the line that says how the machine ended (state_machine.py):
    # smach_ros's heartbeat thread may publish between the two, stamped a moment before the line.
    told = ends(run_of_a_then_b(status(0.7, ROOT, ["A"], ["None"]),
                                line(0.7002, "State machine terminating 'B':'fail':'done'")))
    assert told[-1] == ("terminate", "done", "fail")


def test_a_heartbeat_stamped_just_before_the_terminating_line_does_not_run_the_machine_again():
    told = ends(run_of_a_then_b(status(0.69, ROOT, ["A"], ["B"]),
                                line(0.7, "State machine terminating 'B':'fail':'done'"),
                                status(2.7, ROOT, ["A"], ["None"])))
    assert [kind for kind, _, _ in told] == ["start", "terminate"] and told[-1] == ("terminate", "done", "fail")


def test_without_its_line_a_machine_a_heartbeat_shows_idle_ends_with_what_its_edges_tell():
    told = ends(run_of_a_then_b(status(0.7, ROOT, ["A"], ["None"]), status(2.7, ROOT, ["A"], ["None"])))
    assert told[-1] == ("terminate", "done", "?")
