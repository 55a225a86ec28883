"""`fsmscope export LOG --html OUT.html`: one file that shows a recorded run from disk (file://), with no
server and no network, the way the dashboard shows `fsmscope replay LOG --serve`."""

from __future__ import annotations

import base64
import json
import re
import shutil
import urllib.parse

import fsm
import pytest
from browser_support import ACTIVE_LEAF
from recording_support import cli, record, replay_served
from smach_support import machine
from fsm.logfiles.log_reader import seek
from fsm.observation.schema import state_id
from server import export_html
from server.testing.browser import open_page
from server.testing.polling import wait_for

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


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """(the log of one run of the counting machine, recorded for real with snapshots, and its events)."""
    if not shutil.which("dot"):
        pytest.skip("Graphviz's dot is not installed (make apt)")
    fsm.set_loggers(*(lambda msg: None,) * 4)
    log = tmp_path_factory.mktemp("export") / "counter.jsonl"
    _, events = record(counting_machine(), log, name=NAME, snapshot_every=100)
    return log, events


@pytest.fixture(scope="module")
def exported(recorded):
    """The exported page, with a keyframe every 50 events so that seeks start from several of them."""
    log, _ = recorded
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(export_html, "KEYFRAME_EVERY", 50)
        text = export_html.export_html(str(log))
    out = log.with_suffix(".html")
    out.write_text(text, encoding="utf-8")
    return out


def seq_of(events, kind: str, path: str, nth: int) -> int:
    """The seq of the ``nth`` (from 1) event of ``kind`` at ``path``."""
    return [e["seq"] for e in events if e["kind"] == kind and e["path"] == path][nth - 1]


def embedded(text: str) -> dict:
    return json.loads(re.search(r'<script type="application/json" id="fsmscope-export">(.*?)</script>', text, re.S)[1])


def modules(text: str) -> dict[str, str]:
    """The page's modules by specifier, decoded from the import map's data: URLs."""
    imports = json.loads(re.search(r'<script type="importmap">(.*?)</script>', text, re.S)[1])["imports"]
    return {spec: base64.b64decode(url.split(",", 1)[1]).decode() for spec, url in imports.items()}


# The file.

def test_the_file_holds_no_external_url(exported):
    text = exported.read_text(encoding="utf-8")
    outside_data = re.sub(r'(<script type="application/json" id="fsmscope-export">).*?(</script>)', "", text,
                          flags=re.S)
    url = re.compile(r"(?:https?:)?//[\w.-]+\.[a-z]", re.I)
    assert not url.findall(outside_data)
    assert all(src.startswith("data:") for src in re.findall(r'\b(?:src|href)="([^"]*)"', outside_data))
    svg_namespace = "http://www.w3.org/2000/svg"  # a name in XML, never fetched
    assert {spec: url.findall(source.replace(svg_namespace, "")) for spec, source in modules(text).items()} == \
        {spec: [] for spec in modules(text)}


def test_the_modules_that_talk_to_a_server_are_the_offline_ones(exported):
    page_modules = modules(exported.read_text(encoding="utf-8"))
    importers = [spec for spec, source in page_modules.items() if not spec.startswith("fsmscope/offline/")]
    imported = {m for spec in importers for m in re.findall(r'from\s*"(fsmscope/[^"]+)"', page_modules[spec])}
    assert {"fsmscope/offline/api.js", "fsmscope/offline/stream.js"} <= imported
    assert "fsmscope/stream.js" not in page_modules
    assert "fsmscope/api.js" not in imported


def test_no_event_text_can_end_the_data_script(exported, recorded):
    text = exported.read_text(encoding="utf-8")
    data = text.split('id="fsmscope-export">', 1)[1].rsplit("</script>", 1)[0]
    assert "<" not in data
    notes = [e["changes"]["note"] for e in embedded(text)["machines"][0]["events"]
             if e["kind"] == "userdata" and "note" in e["changes"]]
    assert notes[0] == MARKUP + " loop 1"


def test_the_file_holds_a_drawing_for_the_default_and_every_depth_level(exported):
    drawings = embedded(exported.read_text(encoding="utf-8"))["machines"][0]["graphs"]
    assert [expand for expand, _ in drawings] == [None, ["/SM_ROOT"], ["/SM_ROOT", "/SM_ROOT/SUB"]]
    assert all("<svg" in svg for _, svg in drawings)


def test_the_command_writes_the_file(recorded, tmp_path):
    log, _ = recorded
    out = tmp_path / "run.html"
    done = cli("export", log, "--html", out)
    assert done.returncode == 0, done.stderr
    assert embedded(out.read_text(encoding="utf-8"))["machines"][0]["name"] == NAME


def test_a_log_above_the_size_limit_is_refused_with_the_way_around(recorded, tmp_path):
    log, _ = recorded
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


# The page, from disk, with the network blocked.

def open_file(browser, path, seq: int):
    """The exported page at event ``seq`` (its deep link), every request that is not file: or data: aborted
    (``page.blocked`` lists them), the page's policy violations in ``window.violations``."""
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    page.set_default_timeout(10000)
    page.errors, page.blocked = [], []
    page.on("pageerror", lambda e: page.errors.append(str(e)))

    def only_local(route):
        if route.request.url.startswith(("file:", "data:")):
            route.continue_()
        else:
            page.blocked.append(route.request.url)
            route.abort()

    page.route("**/*", only_local)
    page.add_init_script("window.violations = []; document.addEventListener('securitypolicyviolation',"
                         " (e) => window.violations.push(e.violatedDirective + ' ' + e.blockedURI));")
    page.goto(path.as_uri() + "#m=%s&seq=%d" % (NAME, seq))
    return at_instant(page, seq)


def at_instant(page, seq: int):
    """``page`` once it shows event ``seq``: the instant, the graph and the log row marked."""
    page.wait_for_selector("#graph svg")
    wait_for(lambda: page.evaluate("fsmscope.instant.seq") == seq
             and page.evaluate("document.querySelector('#log .log-row.at')?.dataset.seq") == str(seq),
             10, interval=0.05, what=lambda: "event %d shown; the page is at %r" % (seq, page.evaluate("fsmscope.instant")))
    return page


SHOWN = """(() => {
    const s = fsmscope.status;
    const row = document.querySelector('#log .log-row.at');
    return {
        active: s.activePaths().sort(),
        containers: Object.fromEntries(Object.entries(s.containers).map(([p, c]) => [p, {userdata: c.userdata, changes: c.changes}])),
        log_row: row && [row.dataset.seq, row.querySelector('.kind').textContent, row.querySelector('.msg').textContent],
        userdata_rows: [...document.querySelectorAll('#userdata tr.ud-row')].map((r) => [r.dataset.key, r.className, r.querySelector('td.value').textContent]),
    };
})()"""


def shown(page) -> dict:
    """What the page shows of its instant: active states, userdata and changes, the log row marked, the userdata panel."""
    data = page.evaluate(SHOWN)
    data["graph_leaf"] = page.evaluate(ACTIVE_LEAF)
    return data


def rebuilt(log, seq: int) -> dict:
    """What fsm.logfiles.log_reader.seek says of event ``seq``: active states, userdata and changes."""
    status = seek(log, NAME, seq).status
    return {"active": sorted(p + "/" + a for p, c in status.containers.items() for a in c["active"] if a != "None"),
            "containers": {p: {"userdata": c["userdata"], "changes": c["changes"]} for p, c in status.containers.items()}}


@pytest.fixture
def file_page(browser, exported, recorded):
    """The exported page at the root's 30th userdata event (its note changed there)."""
    seq = seq_of(recorded[1], "userdata", "/SM_ROOT", 30)
    page = open_file(browser, exported, seq)
    yield page
    assert not page.errors
    page.close()


def test_the_page_shows_the_instant_that_log_reader_seek_rebuilds(file_page, recorded):
    log, events = recorded
    seq = seq_of(events, "userdata", "/SM_ROOT", 30)
    page = shown(file_page)
    expected = rebuilt(log, seq)
    assert {k: page[k] for k in expected} == expected
    assert page["graph_leaf"] == state_id("/SM_ROOT/CHECK")
    assert page["log_row"][:2] == [str(seq), "userdata"]
    assert [key for key, cls, _ in page["userdata_rows"] if "changed" in cls] == ["note"]


def test_the_page_makes_no_request_and_breaks_none_of_its_policy(file_page):
    assert file_page.blocked == []
    assert file_page.evaluate("window.violations") == []


def test_a_userdata_value_with_markup_shows_as_text(file_page):
    value = file_page.text_content('#userdata tr.ud-row[data-key="note"] td.value')
    assert value.startswith(json.dumps(MARKUP + " loop 30"))
    assert file_page.query_selector_all("#userdata img, #userdata b, #userdata script") == []
    assert file_page.evaluate("window.pwned") is None


def test_clicking_a_log_row_shows_that_event(file_page, recorded):
    log, events = recorded
    seq = seq_of(events, "transition", "/SM_ROOT/SUB", 30)  # A -> B of the 30th loop
    file_page.click('#log .log-row[data-seq="%d"]' % seq)
    at_instant(file_page, seq)
    assert shown(file_page)["active"] == rebuilt(log, seq)["active"] == ["/SM_ROOT/SUB", "/SM_ROOT/SUB/B"]
    assert file_page.evaluate(ACTIVE_LEAF) == state_id("/SM_ROOT/SUB/B")


@pytest.fixture
def replay_url(recorded):
    """The dashboard's address of `fsmscope replay LOG --serve` serving the same log, in a real process."""
    with replay_served(recorded[0]) as (url, _):
        yield url


def test_the_page_shows_what_the_live_dashboard_shows_at_the_same_event(file_page, browser, replay_url, recorded):
    seq = seq_of(recorded[1], "userdata", "/SM_ROOT", 30)
    live = open_page(browser, replay_url + "#m=%s&seq=%d" % (urllib.parse.quote(NAME), seq))
    try:
        assert shown(at_instant(live, seq)) == shown(file_page)
        assert not live.errors
    finally:
        live.close()


def test_next_transition_steps_into_the_nested_machine(file_page, recorded):
    log, events = recorded
    to_sub = seq_of(events, "transition", "/SM_ROOT", 60)  # the root's CHECK -> SUB after the 30th note
    into_sub = seq_of(events, "start", "/SM_ROOT/SUB", 31)  # then SUB starts its 31st run
    for seq in (to_sub, into_sub):
        file_page.click('#timeline button[title^="Next transition"]')
        at_instant(file_page, seq)
    assert shown(file_page)["active"] == rebuilt(log, into_sub)["active"] == ["/SM_ROOT/SUB", "/SM_ROOT/SUB/A"]


def test_play_runs_the_file_to_the_end_of_the_run(file_page, recorded):
    log, events = recorded
    last = events[-1]["seq"]
    file_page.click("#timeline button.tl-play")
    at_instant(file_page, last)
    wait_for(lambda: not file_page.evaluate("fsmscope.instant.playing"), 5, what="the playhead to stop at the end")
    assert {k: v for k, v in shown(file_page).items() if k in ("active", "containers")} == rebuilt(log, last)
