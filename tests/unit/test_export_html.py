"""`fsmscope export LOG --html OUT.html`: the file it writes (test_browser_export.py opens it in Chromium)."""

from __future__ import annotations

import base64
import json
import re

import pytest
from export_support import LOOPS, MARKUP, NAME, exported_run
from recording_support import cli


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return exported_run(tmp_path_factory)


def embedded(text: str) -> dict:
    return json.loads(re.search(r'<script type="application/json" id="fsmscope-export">(.*?)</script>', text, re.S)[1])


def modules(text: str) -> dict[str, str]:
    """The page's modules by specifier, decoded from the import map's data: URLs."""
    imports = json.loads(re.search(r'<script type="importmap">(.*?)</script>', text, re.S)[1])["imports"]
    return {spec: base64.b64decode(url.split(",", 1)[1]).decode() for spec, url in imports.items()}


def test_the_file_holds_no_external_url(run):
    text = run.html.read_text(encoding="utf-8")
    outside_data = re.sub(r'(<script type="application/json" id="fsmscope-export">).*?(</script>)', "", text,
                          flags=re.S)
    url = re.compile(r"(?:https?:)?//[\w.-]+\.[a-z]", re.I)
    assert not url.findall(outside_data)
    assert all(src.startswith("data:") for src in re.findall(r'\b(?:src|href)="([^"]*)"', outside_data))
    svg_namespace = "http://www.w3.org/2000/svg"  # a name in XML, never fetched
    assert {spec: url.findall(source.replace(svg_namespace, "")) for spec, source in modules(text).items()} == \
        {spec: [] for spec in modules(text)}


def test_the_modules_that_talk_to_a_server_are_the_offline_ones(run):
    page_modules = modules(run.html.read_text(encoding="utf-8"))
    importers = [spec for spec, source in page_modules.items() if not spec.startswith("fsmscope/offline/")]
    imported = {m for spec in importers for m in re.findall(r'from\s*"(fsmscope/[^"]+)"', page_modules[spec])}
    assert {"fsmscope/offline/api.js", "fsmscope/offline/stream.js"} <= imported
    assert "fsmscope/stream.js" not in page_modules
    assert "fsmscope/api.js" not in imported


def test_no_event_text_can_end_the_data_script(run):
    text = run.html.read_text(encoding="utf-8")
    data = text.split('id="fsmscope-export">', 1)[1].rsplit("</script>", 1)[0]
    assert "<" not in data
    notes = [e["changes"]["note"] for e in embedded(text)["machines"][0]["events"]
             if "note" in e.get("changes", {})]
    assert notes[0] == MARKUP + " loop 1"


def test_the_file_holds_a_drawing_for_the_default_and_every_depth_level(run):
    drawings = embedded(run.html.read_text(encoding="utf-8"))["machines"][0]["graphs"]
    assert [expand for expand, _ in drawings] == [None, ["/SM_ROOT"], ["/SM_ROOT", "/SM_ROOT/SUB"]]
    assert all("<svg" in svg for _, svg in drawings)


def test_the_command_writes_the_file(run, tmp_path):
    log = run.log
    out = tmp_path / "run.html"
    done = cli("export", log, "--html", out)
    assert done.returncode == 0, done.stderr
    assert embedded(out.read_text(encoding="utf-8"))["machines"][0]["name"] == NAME


def test_a_log_above_the_size_limit_is_refused_with_the_way_around(run, tmp_path):
    log = run.log
    done = cli("export", log, "--html", tmp_path / "run.html", "--max-mb", "0.001")
    assert done.returncode == 2
    assert "above the limit of 0.0 MB" in done.stderr and "--max-mb" in done.stderr
    assert not (tmp_path / "run.html").exists()


def test_a_log_without_events_is_refused(tmp_path):
    log = tmp_path / "empty.jsonl"
    log.write_text("")
    done = cli("export", log, "--html", tmp_path / "run.html")
    assert done.returncode == 2
    assert "no events" in done.stderr


def test_the_file_holds_the_state_statistics_replay_counts(run):
    stats = embedded(run.html.read_text(encoding="utf-8"))["machines"][0]["stats"]
    assert stats["states"]["/SM_ROOT/SUB/B"]["visits"] == LOOPS
    assert stats["states"]["/SM_ROOT/CHECK"]["last_outcome"] == "done"
    assert stats["complete"] and stats["unvisited"]["visits"] == 0
