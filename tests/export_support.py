"""A recorded run of a nested machine and its export (`fsmscope export`), shared by the tests of the
exported file (test_export_html.py) and of the page it opens in Chromium (test_browser_export.py)."""

from __future__ import annotations

import shutil
from typing import NamedTuple

import fsm
import pytest
from recording_support import record
from smach_support import machine

from fsmscope.server import export_html

LOOPS = 60
MARKUP = '<img src=x onerror="window.pwned = 1"><b>bold</b> </script><script>window.pwned = 2</script>'
NAME = "counter"


def counting_machine():
    """SM_ROOT: SUB (A -> B, B adds 1 to SUB's x) -> CHECK (writes the root's note, markup and the loop
    number) -> SUB again, LOOPS times, then done."""
    loops = [0]

    def add_one(ud):
        ud.x = ud.x + 1
        return "go"

    def check(ud):
        loops[0] += 1
        ud.note = "%s loop %d" % (MARKUP, loops[0])
        return "done" if loops[0] >= LOOPS else "again"

    sub = machine(["ok"], [("A", fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": "B"}),
                           ("B", fsm.CBState(add_one, outcomes=["go"], input_keys=["x"], output_keys=["x"]),
                            {"go": "ok"})])
    sub.userdata.x = 0
    return machine(["done"], [("SUB", sub, {"ok": "CHECK"}),
                              ("CHECK", fsm.CBState(check, outcomes=["again", "done"], output_keys=["note"]),
                               {"again": "SUB", "done": "done"})])


class ExportedRun(NamedTuple):
    log: object  # the recording (a Path)
    events: list  # the events the recorder was given
    html: object  # the exported page (a Path)


def exported_run(tmp_path_factory) -> ExportedRun:
    """One run of the counting machine recorded for real (snapshots every 100 events) and exported with a
    keyframe every 50 events, so that seeks start from several of them."""
    if not shutil.which("dot"):
        pytest.skip("Graphviz's dot is not installed (make apt)")
    fsm.set_loggers(*(lambda msg: None,) * 4)
    log = tmp_path_factory.mktemp("export") / "counter.jsonl"
    _, events = record(counting_machine(), log, name=NAME, snapshot_every=100)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(export_html, "KEYFRAME_EVERY", 50)
        text = export_html.export_html(str(log))
    html = log.with_suffix(".html")
    html.write_text(text, encoding="utf-8")
    return ExportedRun(log, events, html)


def seq_of(events, kind: str, path: str, nth: int) -> int:
    """The seq of the ``nth`` (from 1) event of ``kind`` at ``path``."""
    return [e["seq"] for e in events if e["kind"] == kind and e["path"] == path][nth - 1]


def seq_of_write(events, path: str, key: str, nth: int) -> int:
    """The seq of the ``nth`` (from 1) event at ``path`` that says ``key`` was written (the transition
    or terminate of the step that wrote it)."""
    return [e["seq"] for e in events if e["path"] == path and key in e.get("changes", {})][nth - 1]
