"""A stranger on the fleet's network (a Zenoh session of its own, without the robot's token) can put on
a robot's keys, answer its queries and receive its dashboards' queries: it can neither pose as the
robot, nor answer for it, nor take a control's token, nor play a control again, nor hold the
dashboard's view of the fleet up (fsmscope/fleet/proofs.py)."""

from __future__ import annotations

import fsm
import pytest
import zenoh
from fleet_support import TOKEN, Delivered, free_endpoint, run_published, slow_loop

from fsmscope.fleet.config import session_config
from fsmscope.fleet.robot import ZenohRobot, batch_attachment
from fsm.observation.encoding import dumps
from fsmscope.server.testing.polling import wait_for


@pytest.fixture
def followed():
    """A dashboard following r1's machine (50 events/s), a stranger's session on its network, and what
    the machine's observer was given (the robot's own events)."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    endpoint, robots = free_endpoint(), free_endpoint()
    dash = Delivered(listen=[endpoint])
    robot = ZenohRobot("r1", connect=[endpoint], listen=[robots], token=TOKEN)
    stranger = zenoh.open(session_config(connect=[endpoint, robots]))  # reaches the dashboard and the robot
    sm = slow_loop(100_000, 0.02)
    own, runner = run_published(robot, sm)
    try:
        wait_for(lambda: len(dash.events) >= 5, 10, what="the machine followed")
        yield dash, stranger, own, robot, endpoint
    finally:
        sm.request_preempt()
        runner.join(10)
        robot.close()
        stranger.close()
        dash.watcher.close()


def still_followed(dash: Delivered) -> None:
    """The machine's next 10 events come within 2.5 s: no query of a robot that is not there (each
    waits 5 s for an answer) held the dashboard up."""
    count = len(dash.events)
    wait_for(lambda: len(dash.events) >= count + 10, 2.5, what="the machine still followed")


def delivered_are_the_robots(dash: Delivered, own: list[dict]) -> None:
    robot_seqs = [event["seq"] for event in own]
    assert [event["seq"] for event in dash.events] == robot_seqs[:len(dash.events)]


def test_a_batch_that_does_not_prove_the_robots_token_is_refused_and_counted(followed):
    dash, stranger, own, _, _ = followed
    next_seq = own[-1]["seq"] + 1
    forged = [b"not json", b'[{"seq": 9007199254740991}]', dumps([dict(own[-1], seq=next_seq, kind="log")])]
    for payload in forged:
        stranger.put("fsmscope/r1/loop/events", payload)
    stranger.put("fsmscope/r1/loop/events", forged[1], attachment=batch_attachment("a guess", "fsmscope/r1/loop/events",
                                                                                 "origin", forged[1]))
    wait_for(lambda: dash.watcher.refusals.count == 4, 10, what="the four puts refused")
    still_followed(dash)
    delivered_are_the_robots(dash, own)


def test_a_proven_put_that_is_not_a_robots_batch_is_counted_and_the_watcher_follows_on(followed):
    dash, stranger, own, robot, _ = followed
    key = "fsmscope/r1/loop/events"
    last = own[-1]["seq"]
    for payload in (b"not json", b'{"seq": 1}', b'[{"no": "seq"}]',
                    dumps([dict(own[-1], seq=last + 1), dict(own[-1], seq=9007199254740991)])):
        stranger.put(key, payload, attachment=batch_attachment(TOKEN, key, robot.controls.origin, payload))
    wait_for(lambda: dash.watcher.rejected == 4, 10, what="the four puts rejected")
    still_followed(dash)
    delivered_are_the_robots(dash, own)


def test_events_put_for_a_machine_that_never_announced_itself_are_skipped_at_once(followed):
    dash, stranger, _, _, _ = followed
    before = dash.watcher.unannounced  # r1's first events may have come before its token did
    payload = b'[{"seq": 7}]'
    stranger.put("fsmscope/ghost/m/events", payload,
                 attachment=batch_attachment(TOKEN, "fsmscope/ghost/m/events", "origin", payload))
    still_followed(dash)
    assert dash.watcher.unannounced == before + 1
    assert not any(event["machine"] == "ghost:m" for event in dash.events)


def test_a_strangers_robot_of_the_same_name_is_never_shown(followed):
    dash, _, _, _, endpoint = followed
    before = dash.watcher.refusals.count
    with ZenohRobot("r1", connect=[endpoint], token="the stranger's own") as spoofer:
        spoofed = slow_loop(20, 0.0)
        fsm.attach(spoofed, spoofer, name="spoofed")
        spoofed.execute()
        spoofer.flush()
        wait_for(lambda: dash.watcher.refusals.count > before, 10, what="the spoofer's batches refused")
        wait_for(lambda: ("r1:spoofed", True) in dash.alive, 10, what="the spoofer's token seen")
        still_followed(dash)  # its join was asked, and refused
    assert not any(event["machine"] == "r1:spoofed" for event in dash.events)
    assert "r1:spoofed" not in dash.watcher.controls


def test_sixty_machines_nobody_answers_for_hold_no_new_robot_off(followed):
    dash, stranger, _, _, endpoint = followed
    waiting: list[zenoh.Query] = []  # queries the stranger keeps unanswered: each waits its whole time
    queryable = stranger.declare_queryable("fsmscope/ghost/*/state", zenoh.handlers.FifoChannel(100))
    tokens = [stranger.liveliness().declare_token("fsmscope/ghost/m%d" % i) for i in range(60)]
    try:
        wait_for(lambda: waiting.extend(iter(queryable.try_recv, None)) or len(waiting) == 60, 10,
                 what="the sixty joins asked")
        with ZenohRobot("r2", connect=[endpoint], token=TOKEN) as r2:
            late = slow_loop(3, 0.0)
            fsm.attach(late, r2, name="late")
            late.execute()
            r2.flush()
            wait_for(lambda: any(event["machine"] == "r2:late" for event in dash.events), 3,
                     what="r2's machine joined while the sixty wait")
    finally:
        for token in tokens:
            token.undeclare()
        queryable.undeclare()
        for query in waiting:
            query.drop()


def controls_of(events: list[dict]) -> list[dict]:
    return [event for event in events if event["kind"] == "control"]


def test_a_strangers_queryable_on_the_control_key_gets_no_token_and_its_answer_is_refused(followed):
    dash, stranger, own, robot, _ = followed
    taken: list[tuple[bytes, bytes]] = []

    def answer_for_the_robot(query: zenoh.Query) -> None:
        if query.payload is not None:  # not the test's own query below
            taken.append((query.payload.to_bytes(), query.attachment.to_bytes()))
        query.reply(query.key_expr, b'{"status": 202, "seq": 1}', attachment=bytes(32))

    queryable = stranger.declare_queryable("fsmscope/r1/loop/control", answer_for_the_robot, complete=True)
    try:
        wait_for(lambda: list(dash.watcher.session.get("fsmscope/r1/loop/control", timeout=1.0,
                                                       target=zenoh.QueryTarget.ALL_COMPLETE)), 10,
                 what="the dashboard knows the stranger's queryable")
        answer = dash.watcher.ask("r1", "loop", TOKEN, "preempt", {"reason": "the operator's"}, "operator")
        [control] = controls_of(own)
        assert (answer["status"], answer["seq"]) == (202, control["seq"])  # the robot's answer, not the stranger's
        wait_for(lambda: taken, 5, what="the stranger's queryable asked too")  # in its own thread
        [(payload, proof)] = taken
        assert TOKEN.encode() not in payload + proof
        assert list(stranger.get("fsmscope/r1/loop/control", payload=payload, attachment=proof, timeout=5.0))
        assert robot.controls.refused == 1 and len(controls_of(own)) == 1  # played again: refused
    finally:
        queryable.undeclare()


def test_a_strangers_answer_alone_is_no_answer(followed):
    dash, stranger, _, _, _ = followed
    queryable = stranger.declare_queryable(
        "fsmscope/r9/loop/control", lambda query: query.reply(query.key_expr, b'{"status": 202, "seq": 1}'))
    try:
        assert dash.watcher.ask("r9", "loop", TOKEN, "preempt", {}, "operator") is None
    finally:
        queryable.undeclare()


def test_a_robot_says_the_controls_it_refuses_once_per_doubling_of_their_count(followed, capfd):
    _, stranger, own, robot, _ = followed
    for i in range(300):
        list(stranger.get("fsmscope/r1/loop/control", payload=b'{"token": "a guess %d"}' % i, timeout=5.0))
    lines = [line for line in capfd.readouterr().err.splitlines() if "refused" in line]
    assert robot.controls.refused == 300 and len(lines) == 9  # the 1st, 2nd, 4th, ... 256th
    assert controls_of(own) == []
