"""`fsmscope demo` as a user runs it: a real process, stopped by a signal mid-episode."""

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

FSMSCOPE = [sys.executable, "-m", "server.cli"]


def start_headless_demo(record) -> subprocess.Popen:
    return subprocess.Popen(FSMSCOPE + ["demo", "--headless", "--record", str(record)], cwd=ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True)


def wait_until_running(record, timeout: float = 60.0) -> None:
    """Until the log holds a first transition (the arm is moving)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if record.exists() and '"kind":"transition"' in record.read_text():
            return
        time.sleep(0.2)
    raise TimeoutError("the demo never started moving")


@pytest.mark.timeout(120)
@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_signal_stops_the_demo_with_its_log_closed_and_complete(tmp_path, signum):
    record = tmp_path / "demo.jsonl"
    proc = start_headless_demo(record)
    wait_until_running(record)
    os.killpg(proc.pid, signum)
    output, _ = proc.communicate(timeout=30)
    assert proc.returncode == 130, output
    assert re.search(r"\d+ episode\(s\) recorded to ", output)
    replay = subprocess.run(FSMSCOPE + ["replay", str(record), "--json"], cwd=ROOT, capture_output=True, text=True)
    assert replay.returncode == 0, replay.stdout + replay.stderr  # every run ended with an outcome
    summary = json.loads(replay.stdout)
    assert summary["machines"]["pick_place"]["outcome"] in ("preempted", "succeeded")
    assert not summary.get("problems"), summary["problems"]  # no cut-off or corrupt line
