"""The demo's episode loop keeps an operator's stop: a preempt pressed in the pause between two
episodes holds the loop until Start (it used to be lost with a 409), and "stop after this
episode" lets the running one finish first. On the demo the tests share (tests/demo/conftest.py: ``demo``,
real time: episodes of several seconds with a pause of 1 s between them)."""

from __future__ import annotations

import time

import pytest
from demo_support import wait_for_a_fresh_episode

from .test_demo_process import api, wait_for_machine


def runs_between(demo, seconds: float) -> int:
    """How many runs began in the next ``seconds`` (0 or 1): the arm settling still records its pose
    on the machine's clock, so the events' seq is no measure."""
    first = api(demo, "GET", "/api/machines/pick_place/status")[1]["run_seq"]
    time.sleep(seconds)
    return int(api(demo, "GET", "/api/machines/pick_place/status")[1]["run_seq"] != first)


@pytest.mark.timeout(120)
def test_a_preempt_between_episodes_holds_the_loop_until_start(demo):
    wait_for_machine(demo, lambda m: m["running"])
    wait_for_machine(demo, lambda m: not m["running"], timeout=60)  # the pause after the first episode
    status, answer = api(demo, "POST", "/api/machines/pick_place/preempt", {"reason": "between episodes"})
    assert status == 202 and isinstance(answer["seq"], int)
    assert runs_between(demo, 2.0) == 0
    assert wait_for_machine(demo, lambda m: True)["outcome"] != "preempted"  # it came between, not during
    assert api(demo, "POST", "/api/machines/pick_place/start", {})[0] == 202
    wait_for_machine(demo, lambda m: m["running"])


@pytest.mark.timeout(120)
def test_stop_after_this_episode_lets_it_finish_then_waits_for_start(demo):
    wait_for_a_fresh_episode(demo)  # seconds of it ahead: the hold lands in it
    assert wait_for_machine(demo, lambda m: m["running"])["can_hold"]
    status, _ = api(demo, "POST", "/api/machines/pick_place/hold", {"reason": "lunch"})
    assert status == 202 and wait_for_machine(demo, lambda m: True)["held"]
    finished = wait_for_machine(demo, lambda m: not m["running"])
    assert finished["outcome"] in ("succeeded", "aborted")  # it ran to its own end: not preempted
    assert runs_between(demo, 1.5) == 0
    assert api(demo, "POST", "/api/machines/pick_place/start", {})[0] == 202
    assert not wait_for_machine(demo, lambda m: m["running"])["held"]
