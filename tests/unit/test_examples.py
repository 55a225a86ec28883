"""The examples: each runs in-process with the expected outcome, and under ``fsmscope run``."""

import json
import os
import threading

import fsm
import pytest
from fsm.ros.bus import get_bus
from fsm.logfiles.log_reader import read_events
from fsm.logfiles.summary import summarize

from recording_support import EXAMPLES, FAST, cli, load_example, record
from fsmscope.server.testing.polling import wait_for


def test_foo_bar_loops_three_times_then_ends_in_end(tmp_path):
    outcome, events = record(load_example("foo_bar")["build"](), tmp_path / "r.jsonl")
    assert outcome == "end"
    assert [e["to"] for e in events if e["kind"] == "transition"] == ["BAR", "FOO"] * 3


def test_retry_abc_counts_every_attempt_and_is_seedable(capsys):
    main = load_example("retry_abc")["main"]
    outcome, counts = main(["--seed", "3"])
    assert outcome == "succeeded"
    assert counts["A_count"] >= counts["B_count"] >= counts["C_count"] >= 1
    assert main(["--seed", "3"])[1] == counts
    assert "A_count=%(A_count)d B_count=%(B_count)d C_count=%(C_count)d" % counts in capsys.readouterr().out


def test_service_action_counts_the_square_with_feedback(tmp_path, monkeypatch):
    monkeypatch.setenv("FSMSCOPE_TIME_SCALE", "0.01")
    example = load_example("service_action")
    service, server = example["start_servers"](0.01)
    try:
        sm = example["build"](__import__("random").Random(5))
        outcome, events = record(sm, tmp_path / "r.jsonl")
    finally:
        server.shutdown()
        service.shutdown()
    assert outcome == "succeeded"
    seconds = sm.userdata.seconds
    assert seconds in (1, 4, 9)
    assert sm.userdata.count_result == {"seconds_counted": seconds}
    feedback = [e for e in events if e["kind"] == "feedback"]
    assert [f["feedback"]["seconds_elapsed"] for f in feedback] == list(range(1, seconds + 1))


def test_nested_monitor_preempts_itself_when_run_standalone():
    assert load_example("nested_monitor")["main"](["--time-scale", "0.01", "--action-seconds", "1000"]) == "preempted"


def test_nested_monitor_is_preempted_by_a_message_from_outside():
    example = load_example("nested_monitor")
    server = example["start_action_server"](0.01)
    sm = example["build"](0.01, action_seconds=1000, stop_after=0)
    started = threading.Event()
    sm["WORK"].register_start_cb(lambda ud, initial: started.set())
    result = []
    runner = threading.Thread(target=lambda: result.append(sm.execute()))
    runner.start()
    try:
        assert started.wait(5)

        # the monitor subscribes as the Concurrence starts its children: publish until it listens
        def stopped_by_a_message() -> bool:
            get_bus().publish("sm_stop", {"reason": "test"})
            runner.join(0.02)
            return bool(result)

        wait_for(stopped_by_a_message, 4.0, interval=0, what="the machine to end on an sm_stop message")
    finally:
        runner.join(5)
        server.shutdown()
    assert result == ["preempted"]


@pytest.mark.parametrize("name, outcome", [("foo_bar", "end"), ("retry_abc", "succeeded"),
                                           ("service_action", "succeeded"), ("nested_monitor", "preempted")])
def test_example_runs_under_fsmscope_run_and_replays(tmp_path, name, outcome):
    log = tmp_path / (name + ".jsonl")
    done = cli("run", os.path.join(EXAMPLES, name + ".py"), "--record", log, env=FAST)
    assert done.returncode == 0, done.stderr
    replay = cli("replay", log, "--json")
    assert replay.returncode == 0
    assert json.loads(replay.stdout)["machines"][name]["outcome"] == outcome
