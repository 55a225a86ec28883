"""The page `fsmscope export LOG --html OUT.html` writes, opened from disk (file://) in Chromium with every
request that is not file: or data: aborted: it shows a recorded run as the served dashboard
(`fsmscope replay LOG --serve`) shows it, and as fsm.logfiles.log_reader.seek rebuilds it."""

from __future__ import annotations

import json
import urllib.parse

import fsm
import pytest
from browser_support import ACTIVE_LEAF
from export_support import LOOPS, MARKUP, NAME, exported_run, seq_of, seq_of_write
from recording_support import record, replay_served
from fsm.logfiles.log_reader import seek
from fsm.observation.schema import container_id, state_id
from fsmscope.server import export_html
from fsmscope.server.testing.big_machine import big_machine
from fsmscope.server.testing.browser import PAGE_WAIT_MS, open_page
from fsmscope.server.testing.polling import wait_for


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return exported_run(tmp_path_factory)


def open_file(browser, path, seq: int):
    """The exported page at event ``seq`` (its deep link), every request that is not file: or data: aborted
    (``page.blocked`` lists them), the page's policy violations in ``window.violations``."""
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    page.set_default_timeout(PAGE_WAIT_MS)
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


ACTIVE_DRAWN = "[...document.querySelectorAll('#graph g.active')].map(g => g.id).sort()"


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
def file_page(browser, run):
    """The exported page at the root's 30th write of its note (CHECK -> SUB of the 30th loop)."""
    page = open_file(browser, run.html, seq_of_write(run.events, "/SM_ROOT", "note", 30))
    yield page
    assert not page.errors
    page.close()


def test_the_page_shows_the_instant_that_log_reader_seek_rebuilds(file_page, run):
    log, events = run.log, run.events
    seq = seq_of_write(events, "/SM_ROOT", "note", 30)
    page = shown(file_page)
    expected = rebuilt(log, seq)
    assert {k: page[k] for k in expected} == expected
    # CHECK -> SUB: SUB is active and not started yet, no leaf is
    assert file_page.evaluate(ACTIVE_DRAWN) == [container_id("/SM_ROOT"), container_id("/SM_ROOT/SUB")]
    assert page["log_row"][:2] == [str(seq), "transition"]
    assert page["log_row"][2].startswith("State machine transitioning 'CHECK':'again'-->'SUB' · Userdata: note = ")
    assert [key for key, cls, _ in page["userdata_rows"] if "changed" in cls] == ["note"]


def test_the_page_makes_no_request_and_breaks_none_of_its_policy(file_page):
    assert file_page.blocked == []
    assert file_page.evaluate("window.violations") == []


def test_a_userdata_value_with_markup_shows_as_text(file_page):
    value = file_page.text_content('#userdata tr.ud-row[data-key="note"] td.value')
    assert value.startswith(json.dumps(MARKUP + " loop 30"))
    assert file_page.query_selector_all("#userdata img, #userdata b, #userdata script") == []
    assert file_page.evaluate("window.pwned") is None


def test_clicking_a_log_row_shows_that_event(file_page, run):
    log, events = run.log, run.events
    seq = seq_of(events, "transition", "/SM_ROOT/SUB", 30)  # A -> B of the 30th loop
    file_page.click('#log .log-row[data-seq="%d"]' % seq)
    at_instant(file_page, seq)
    assert shown(file_page)["active"] == rebuilt(log, seq)["active"] == ["/SM_ROOT/SUB", "/SM_ROOT/SUB/B"]
    assert file_page.evaluate(ACTIVE_LEAF) == state_id("/SM_ROOT/SUB/B")


@pytest.fixture
def replay_url(run):
    """The dashboard's address of `fsmscope replay LOG --serve` serving the same log, in a real process."""
    with replay_served(run.log) as (url, _):
        yield url


def test_the_page_shows_what_the_live_dashboard_shows_at_the_same_event(file_page, browser, replay_url, run):
    seq = seq_of_write(run.events, "/SM_ROOT", "note", 30)
    live = open_page(browser, replay_url + "#m=%s&seq=%d" % (urllib.parse.quote(NAME), seq))
    try:
        assert shown(at_instant(live, seq)) == shown(file_page)
        assert not live.errors
    finally:
        live.close()


def test_next_transition_steps_into_the_nested_machine(file_page, run):
    log, events = run.log, run.events
    into_sub = seq_of(events, "start", "/SM_ROOT/SUB", 31)  # after the 30th note's CHECK -> SUB, its 31st run
    file_page.click('#timeline button[title^="Next transition"]')
    at_instant(file_page, into_sub)
    assert shown(file_page)["active"] == rebuilt(log, into_sub)["active"] == ["/SM_ROOT/SUB", "/SM_ROOT/SUB/A"]


def test_play_runs_the_file_to_the_end_of_the_run(file_page, run):
    log, events = run.log, run.events
    last = events[-1]["seq"]
    file_page.click("#timeline button.tl-play")
    at_instant(file_page, last)
    wait_for(lambda: not file_page.evaluate("fsmscope.instant.playing"), 5, what="the playhead to stop at the end")
    assert {k: v for k, v in shown(file_page).items() if k in ("active", "containers")} == rebuilt(log, last)


def test_details_show_the_state_statistics_of_the_recording(file_page):
    file_page.click('#tree .tree-row[data-path="/SM_ROOT/SUB/B"]')
    file_page.click("#details > summary")
    wait_for(lambda: file_page.text_content("#details .details-visits") == str(LOOPS), 5,
             what=lambda: "B's visits: %r" % file_page.text_content("#details .details-stats"))
    assert file_page.text_content("#details .details-last-outcome") == "go"


@pytest.fixture(scope="module")
def big_run(tmp_path_factory):
    """A recorded run of a machine too big to draw open (286 states: "auto" leaves its containers
    closed), exported: (the page's file, the seq of a transition two containers deep in it)."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    sm, stop = big_machine(branching=2, depth=3, leaves=40)
    seen = []

    def stop_after_3000_events(event):
        seen.append(event)
        if len(seen) >= 3000:
            stop.set()

    fsm.attach(sm, stop_after_3000_events, name="big")
    log = tmp_path_factory.mktemp("big-export") / "big.jsonl"
    record(sm, log, name="big")
    html = log.with_suffix(".html")
    html.write_text(export_html.export_html(str(log)), encoding="utf-8")
    deep = [e["seq"] for e in seen if e["kind"] == "transition" and e["path"].count("/") == 3]
    return html, deep[len(deep) // 2]


def test_an_exported_big_machine_is_drawn_without_asking_for_drawings_the_file_lacks(browser, big_run):
    html, seq = big_run
    page = browser.new_page(viewport={"width": 1280, "height": 800})
    try:
        page.goto(html.as_uri() + "#m=big&seq=%d" % seq)
        page.wait_for_selector("#graph svg")
        wait_for(lambda: page.evaluate("fsmscope.instant.seq") == seq, 10,
                 what=lambda: "event %d shown; the page is at %r" % (seq, page.evaluate("fsmscope.instant")))
        page.wait_for_timeout(1000)  # semantic zoom would have asked for the running containers by now
        assert page.evaluate("fsmscope.status.activePaths().length") > 1
        assert page.text_content("#notice") == ""
        assert page.eval_on_selector_all("#graph g.cluster", "gs => gs.map((g) => g.id)") == ["c:/SM_ROOT"]
    finally:
        page.close()
