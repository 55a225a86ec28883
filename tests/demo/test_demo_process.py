"""`fsmscope demo` as a user runs it: a real process, stopped by a signal mid-episode (headless), and
preempted and started again over REST (the demo the tests share, tests/demo/conftest.py: ``demo``)."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time

import pytest
from browser_support import ROOT
from demo_support import wait_for_a_fresh_episode
from fsmscope.server.testing.polling import wait_for

FSMSCOPE = [sys.executable, "-m", "fsmscope"]


def start_headless_demo(record) -> subprocess.Popen:
    return subprocess.Popen(FSMSCOPE + ["demo", "--headless", "--record", str(record)], cwd=ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True)


def wait_until_running(record, timeout: float = 60.0) -> None:
    """Until the log holds a first transition (the arm is moving)."""
    wait_for(lambda: record.exists() and '"kind":"transition"' in record.read_text(), timeout, interval=0.2,
             what="the demo to start moving")


@pytest.mark.timeout(120)
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_signal_stops_the_demo_with_its_log_closed_and_complete(tmp_path, signum):
    record = tmp_path / "demo.jsonl"
    proc = start_headless_demo(record)
    wait_until_running(record)
    os.killpg(proc.pid, signum)
    output, _ = proc.communicate(timeout=30)
    assert proc.returncode == 128 + signum, output
    assert re.search(r"\d+ episode\(s\) recorded to ", output)
    replay = subprocess.run(FSMSCOPE + ["replay", str(record), "--json"], cwd=ROOT, capture_output=True, text=True)
    assert replay.returncode == 0, replay.stdout + replay.stderr  # every run ended with an outcome
    summary = json.loads(replay.stdout)
    assert summary["machines"]["pick_place"]["outcome"] in ("preempted", "succeeded")
    assert not summary.get("problems"), summary["problems"]  # no cut-off or corrupt line


def api(demo, method: str, path: str, body: dict | None = None) -> tuple[int, dict]:
    import httpx

    answer = httpx.request(method, demo.url.split("/?")[0] + path, json=body,
                           headers={"Authorization": "Bearer " + demo.token}, timeout=10)
    return answer.status_code, answer.json()


def wait_for_machine(demo, predicate, timeout: float = 30.0) -> dict:
    def pick_place_as_wanted() -> dict | None:
        machine = {m["name"]: m for m in api(demo, "GET", "/api/machines")[1]}.get("pick_place")
        return machine if machine is not None and predicate(machine) else None

    return wait_for(pick_place_as_wanted, timeout, interval=0.1, what="pick_place to reach the expected state")


@pytest.mark.timeout(120)
def test_preempting_the_demo_halts_the_episode_and_start_runs_the_next(demo):
    wait_for_a_fresh_episode(demo)  # seconds of it ahead: the preempt lands in it
    status, answer = api(demo, "POST", "/api/machines/pick_place/preempt", {"reason": "test"})
    assert status == 202 and isinstance(answer["seq"], int)
    stopped = wait_for_machine(demo, lambda m: not m["running"])
    assert stopped["outcome"] == "preempted"
    time.sleep(1.0)  # the loop waits for Start instead of going on by itself
    assert not wait_for_machine(demo, lambda m: True)["running"]
    assert api(demo, "POST", "/api/machines/pick_place/start", {})[0] == 202
    wait_for_machine(demo, lambda m: m["running"])
