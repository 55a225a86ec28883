"""`fsmscope replay` on well-formed JSON events of the wrong shape: each is skipped and reported
with its line number, like a corrupt line, and every valid event still replays."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from browser_support import ROOT
from event_support import ev, flat_root, run_of

ILL_SHAPED = {
    "initial is a number": ev(2, "start", initial=5, active=["A"], userdata={}),
    "active is a number": ev(3, "transition", **{"from": "A", "outcome": "go", "to": "B", "active": 7}),
    "a transition without from": ev(3, "transition", outcome="go", to="B", active=["B"]),
    "root is a string": ev(1, "structure", root="nope"),
    "t is a word": dict(ev(4, "terminate", last=["B"], outcome="done"), t="yesterday"),
}


def replay(path, *args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "fsmscope", "replay", str(path), *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("what", ILL_SHAPED)
def test_an_ill_shaped_event_is_skipped_with_its_line_number(tmp_path, what):
    events = run_of(flat_root("A", "B"))
    log = tmp_path / "run.jsonl"
    log.write_text("\n".join(json.dumps(e) for e in events[:2] + [ILL_SHAPED[what]] + events[2:]) + "\n")
    done = replay(log, "--no-time")
    assert "Traceback" not in done.stderr
    assert "skipped line 3: invalid event:" in done.stderr
    assert "State machine terminating 'B':'go':'done'" in done.stdout
    assert done.returncode == 0, done.stderr
