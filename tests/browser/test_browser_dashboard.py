"""The dashboard in a real Chromium against a real server serving a real running machine.

The server runs in a child process (this file run as a script) so that a test can kill it
outright and start it again on the same port, the way a crashed `fsmscope run` comes back.
"""

from __future__ import annotations

import json
import os
import secrets
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest
from browser_support import ACTIVE_LEAF, filter_log
from fsmscope.server.testing.browser import PAGE_WAIT_MS
from fsmscope.server.testing.demo_process import free_port
from fsmscope.server.testing.polling import wait_for

XSS = "<img src=x onerror=alert(1)>"
ROOT = Path(__file__).resolve().parents[2]
SHOTS = ROOT / "build" / "screenshots"


# ---------------------------------------------------------------- the machine (also used by the child process)

def build_machine():
    """SM_ROOT: COUNT -> NESTED(A -> B) -> PAR(LEFT | RIGHT) -> XSS -> COUNT ..., until preempted."""
    import fsm

    class Step(fsm.State):
        def __init__(self, seconds=0.12, outcome="next", count=False):
            fsm.State.__init__(self, [outcome, "preempted"], io_keys=["count"] if count else [])
            self.seconds, self.outcome, self.count = seconds, outcome, count

        def execute(self, ud):
            if self.count:
                ud.count = ud.count + 1
            end = time.monotonic() + self.seconds
            while time.monotonic() < end:
                if self.preempt_requested():
                    self.service_preempt()
                    return "preempted"
                time.sleep(0.01)
            return self.outcome

    nested = fsm.StateMachine(outcomes=["ok", "preempted"], input_keys=["count"])
    with nested:
        fsm.StateMachine.add("A", Step(), transitions={"next": "B"})
        fsm.StateMachine.add("B", Step(outcome="ok"), transitions={"ok": "ok"})
    par = fsm.Concurrence(outcomes=["ok", "preempted"], default_outcome="ok",
                          outcome_map={"ok": {"LEFT": "ok", "RIGHT": "ok"}, "preempted": {"LEFT": "preempted"}})
    with par:
        fsm.Concurrence.add("LEFT", Step(0.15, "ok"))
        fsm.Concurrence.add("RIGHT", Step(0.1, "ok"))
    sm = fsm.StateMachine(outcomes=["done", "preempted"])
    sm.userdata.count = 0
    sm.userdata.note = XSS
    with sm:
        fsm.StateMachine.add("COUNT", Step(count=True), transitions={"next": "NESTED"})
        fsm.StateMachine.add("NESTED", nested, transitions={"ok": "PAR"})
        fsm.StateMachine.add("PAR", par, transitions={"ok": XSS})
        fsm.StateMachine.add(XSS, Step(), transitions={"next": "COUNT"})
    return sm


def serve(port: int, token: str) -> None:
    """Child process: serve the machine on a fixed port and token, run it, keep serving."""
    import threading

    import fsm
    from fsmscope.server.introspection_server import IntrospectionServer

    quiet = lambda msg: None  # noqa: E731
    fsm.set_loggers(quiet, quiet, quiet, quiet)
    sm = build_machine()
    IntrospectionServer("demo", sm, "/SM_ROOT", port=port, token=token).start()
    sm.execute()
    threading.Event().wait()


# ---------------------------------------------------------------- fixtures

class ServerProcess:
    def __init__(self, log_dir: Path) -> None:
        self.port = free_port()
        self.token = secrets.token_urlsafe(24)
        self.log = log_dir / "server.log"
        self.proc: subprocess.Popen | None = None

    @property
    def base(self) -> str:
        return "http://127.0.0.1:%d" % self.port

    @property
    def url(self) -> str:
        return self.base + "/?token=" + self.token

    def start(self) -> None:
        with open(self.log, "ab") as log:
            # The child imports this file's helpers from tests/, beside the folder it runs from.
            path = os.pathsep.join(filter(None, [str(ROOT / "tests"), os.environ.get("PYTHONPATH")]))
            self.proc = subprocess.Popen([sys.executable, __file__, "--serve", str(self.port), self.token],
                                         cwd=str(ROOT), stdout=log, stderr=log, env=dict(os.environ, PYTHONPATH=path))
        wait_for(self._answers, 15, interval=0.05,
                 what=lambda: "the server to answer; its log: " + self.log.read_text()[-2000:])

    def _answers(self) -> bool:
        if self.proc.poll() is not None:
            raise RuntimeError("server exited: " + self.log.read_text()[-2000:])
        try:
            with urllib.request.urlopen(self.base + "/api/health", timeout=0.5):
                return True
        except OSError:
            return False

    def kill(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(5)

    def get(self, path: str):
        req = urllib.request.Request(self.base + path, headers={"Authorization": "Bearer " + self.token})
        with urllib.request.urlopen(req, timeout=5) as resp:
            return json.loads(resp.read())


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    pytest.importorskip("fsmscope.server.introspection_server", reason="the backend (server/) is not there yet")
    proc = ServerProcess(tmp_path_factory.mktemp("server"))
    proc.start()
    yield proc
    proc.kill()


@pytest.fixture
def page(browser, server):
    if server.proc.poll() is not None:  # a previous test left it dead
        server.start()
    context = browser.new_context(viewport={"width": 1280, "height": 800})
    page = context.new_page()
    page.set_default_timeout(PAGE_WAIT_MS)
    page.dialogs = []
    page.on("dialog", lambda d: (page.dialogs.append(d.message), d.dismiss()))
    page.errors = []
    page.on("pageerror", lambda e: page.errors.append(str(e)))
    page.goto(server.url)
    page.wait_for_selector("#badge.live")
    page.wait_for_selector("#graph svg")
    yield page
    if page.is_visible("#lease-release"):  # the page took control: give it up, or the deadman pauses the machine
        page.click("#lease-release")
        page.wait_for_selector("#lease-state:has-text('nobody controls')")
    context.close()
    assert not page.errors, page.errors


def active_leaf(page) -> str | None:
    """The deepest state path drawn active in the graph."""
    return page.evaluate(ACTIVE_LEAF)


def ensure_running(page, server) -> None:
    if not server.get("/api/machines")[0]["running"]:
        page.click("#start-btn")
    page.wait_for_selector("#run-state.running")


# ---------------------------------------------------------------- tests

def test_graph_follows_the_active_state(page, server):
    ensure_running(page, server)
    # Every level: the root's active child and the nested machine's active child light up.
    # Both at one instant (the machine moves on: NESTED ends between two separate looks).
    page.wait_for_function("() => document.querySelector('[id=\"s:/SM_ROOT/NESTED/A\"].active, "
                           "[id=\"s:/SM_ROOT/NESTED/B\"].active') !== null"
                           " && document.getElementById('c:/SM_ROOT/NESTED').classList.contains('active')")
    first = active_leaf(page)
    page.wait_for_function("(first) => { const ids = [...document.querySelectorAll('#graph g.node.active')]"
                           ".map(g => g.id); return ids.length && !ids.includes(first); }", arg=first)
    # Concurrence children side by side, each active while it runs.
    page.wait_for_selector('[id="s:/SM_ROOT/PAR/LEFT"].active')
    # Status changes never re-layout: the same SVG element stays in place.
    svg = page.evaluate_handle("document.querySelector('#graph svg')")
    page.wait_for_selector('[id="s:/SM_ROOT/COUNT"].active')
    assert page.evaluate("(svg) => svg === document.querySelector('#graph svg')", svg)
    # The tree and the badge agree.
    page.wait_for_selector('.tree-row.active[data-path="/SM_ROOT"]')
    assert "ev/s" in page.text_content("#badge")
    SHOTS.mkdir(parents=True, exist_ok=True)
    page.screenshot(path=str(SHOTS / "dashboard-1280x800.png"))
    page.set_viewport_size({"width": 1920, "height": 1080})
    page.wait_for_timeout(200)
    assert page.evaluate("document.documentElement.scrollWidth <= innerWidth")
    page.screenshot(path=str(SHOTS / "dashboard-1920x1080.png"))


def test_container_userdata_highlights_changed_keys(page, server):
    ensure_running(page, server)
    page.click('.tree-row[data-path="/SM_ROOT/NESTED"] .label')
    page.wait_for_selector('#userdata tr[data-key="count"]')
    assert page.input_value("#ud-container") == "/SM_ROOT/NESTED"
    page.select_option("#ud-container", "/SM_ROOT")
    # COUNT writes `count`; the transition it causes highlights the key.
    page.wait_for_selector('#userdata tr.changed[data-key="count"]')
    assert page.text_content('#userdata tr[data-key="note"] td') == json.dumps(XSS)


def test_event_log_filters_and_selects(page, server):
    ensure_running(page, server)
    filter_log(page, "/SM_ROOT/NESTED", ["transition"])
    page.wait_for_selector("#log .log-row")
    kinds = page.eval_on_selector_all("#log .log-row .kind", "els => els.map(e => e.textContent)")
    paths = page.eval_on_selector_all("#log .log-row .path", "els => els.map(e => e.textContent)")
    assert set(kinds) == {"transition"} and set(paths) == {"/SM_ROOT/NESTED"}
    assert "State machine transitioning 'A':'next'-->'B'" in page.text_content("#log")
    page.click("#log .log-row >> nth=-1")
    assert page.evaluate("window.fsmscope.selected") == "/SM_ROOT/NESTED/B"
    page.wait_for_selector('.tree-row.selected[data-path="/SM_ROOT/NESTED/B"]')


def test_names_and_values_render_as_text(page, server):
    ensure_running(page, server)
    row = page.wait_for_selector('.tree-row[data-path="/SM_ROOT/%s"] .label' % XSS)
    assert row.text_content() == XSS
    page.wait_for_selector('[id="s:/SM_ROOT/%s"].active' % XSS)
    graph_text = page.text_content("#graph")
    assert XSS in graph_text
    filter_log(page, kinds=["transition"])
    page.wait_for_function("(x) => document.getElementById('log').textContent.includes(x)", arg=XSS)
    # Nothing was parsed as markup anywhere: no <img>, no handler ran.
    assert page.evaluate("document.querySelectorAll('img').length") == 0
    assert page.evaluate("document.querySelectorAll('[onerror]').length") == 0
    assert page.dialogs == []


def test_svg_is_sanitized_before_it_is_inlined(page):
    evil = ('<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink">'
            '<script>alert(1)</script><g id="s:/R/X" class="node" onclick="alert(2)">'
            '<a xlink:href="javascript:alert(3)"><text>X</text></a><set attributeName="onmouseover" to="alert(4)"/></g>'
            '<foreignObject><div xmlns="http://www.w3.org/1999/xhtml"><img src="x" onerror="alert(5)"/></div>'
            '</foreignObject><image href="http://example.invalid/x.png"/></svg>')
    markup = page.evaluate("""async (text) => {
        const { parseSvg } = await import('/graph.js');
        return parseSvg(text).outerHTML;
    }""", evil)
    for bad in ("script", "onclick", "javascript", "foreignObject", "onerror", "<set", "<image", "example.invalid"):
        assert bad not in markup, (bad, markup)
    assert 'id="s:/R/X"' in markup and ">X</text>" in markup


def test_without_token_the_page_says_so(browser, server):
    context = browser.new_context()
    try:
        page = context.new_page()
        page.goto(server.base + "/")
        page.wait_for_selector("#banner:has-text('Not authorized')")
    finally:
        context.close()


def test_set_initial_state_validates_json(page, server):
    page.click('.tree-row[data-path="/SM_ROOT/NESTED/B"] .label', button="right")
    page.click("#menu button:has-text('Set as initial state')")
    page.wait_for_selector("#initial-dialog[open]")
    page.fill("#initial-dialog textarea", '{"count": ')
    assert "Not valid JSON" in page.text_content("#initial-dialog .dlg-error")
    assert page.is_disabled("#initial-dialog button[value=send]")
    page.fill("#initial-dialog textarea", "[1, 2]")
    assert "must be a JSON object" in page.text_content("#initial-dialog .dlg-error")
    page.fill("#initial-dialog textarea", '{"count": 7}')
    page.click("#initial-dialog button[value=send]")
    page.wait_for_selector("#initial-dialog:not([open])", state="attached")
    page.wait_for_selector("#notice:has-text('Initial state of /SM_ROOT/NESTED set to B')")
    filter_log(page, kinds=["control"])
    page.wait_for_selector("#log .log-row:has-text('initial-state')")


def test_preempt_then_start(page, server):
    ensure_running(page, server)
    page.click("#preempt-btn")
    page.wait_for_selector("#preempt-dialog[open]")
    page.click("#preempt-confirm")
    page.wait_for_selector("#notice:has-text('finished'), #notice:has-text('Preempt accepted')")
    page.wait_for_selector("#run-state:has-text('finished: preempted')")
    text = page.text_content("#notice")
    assert "Preempt accepted (event " in text and "outcome 'preempted'" in text, text
    page.wait_for_selector('[id="o:/SM_ROOT:preempted"].reached')
    assert page.is_disabled("#preempt-btn")
    page.wait_for_selector("#start-btn:not([disabled])")
    page.click("#start-btn")
    page.wait_for_selector("#notice:has-text('Start ')", timeout=15000)
    assert "Start accepted" in page.text_content("#notice"), page.text_content("#notice")
    page.wait_for_selector("#run-state.running", timeout=15000)
    wait_for(lambda: page.locator("#graph g.node.active").count(), 30, interval=0.1,
             what=lambda: "a state lit in the new run; the page shows %r" % page.evaluate(
                 "({badge: document.getElementById('badge').className, run: window.fsmscope.status.run,"
                 " active: Object.values(window.fsmscope.status.toDict().containers).map((c) => c.active),"
                 " lit: document.querySelectorAll('#graph .active').length})"))


def test_page_recovers_when_the_server_restarts(page, server):
    ensure_running(page, server)
    run = page.evaluate("window.fsmscope.status.run")
    server.kill()
    page.wait_for_selector("#badge:not(.live)")
    server.start()  # same port and token: a new process, its seqs start again from 1
    page.wait_for_selector("#badge.live", timeout=15000)
    page.wait_for_selector("#run-state.running")
    # Events flow again: the active state keeps moving, the page follows the new run.
    first = active_leaf(page)
    page.wait_for_function("(first) => { const ids = [...document.querySelectorAll('#graph g.node.active')]"
                           ".map(g => g.id); return ids.length && !ids.includes(first); }", arg=first)
    assert page.evaluate("window.fsmscope.status.run") != run


def test_js_reducer_matches_python(page):
    """fsm.observation.status.Status and fsmscope/static/status.js rebuild the same state from the same events, over two runs."""
    import fsm
    from fsm.observation.status import rebuild

    import threading

    fsm.set_loggers(*(lambda msg: None,) * 4)
    sm = build_machine()
    events: list[dict] = []
    lap, second_run_moved = threading.Event(), threading.Event()

    def observe(event):
        events.append(event)
        moved_to = event.get("to") if event["kind"] == "transition" else None
        if moved_to == "COUNT":
            lap.set()
        elif moved_to == "NESTED" and event["run"] != events[0]["run"]:
            second_run_moved.set()

    def run_until(mark):
        runner = threading.Thread(target=sm.execute)
        runner.start()
        try:
            assert mark.wait(10)
        finally:
            sm.request_preempt()  # from another thread, as the server does
            runner.join(10)

    reporter = fsm.attach(sm, observe, name="lap")
    try:
        run_until(lap)  # the first run goes through every container
        run_until(second_run_moved)  # the second is preempted in NESTED: PAR does not run again
    finally:
        reporter.remove_observer(observe)  # leave no log listener behind for other tests
    want = rebuild(events)["lap"].to_dict()
    got = page.evaluate("""async (events) => {
        const { Status } = await import('/status.js');
        const s = new Status('lap');
        for (const e of events) s.apply(e);
        return s.toDict();
    }""", json.loads(json.dumps(events)))
    assert got == json.loads(json.dumps(want))
    assert got["outcome"] == "preempted"
    assert got["containers"]["/SM_ROOT/PAR"]["outcome"] is None  # what it reached in the first run is gone


if __name__ == "__main__" and sys.argv[1:2] == ["--serve"]:
    serve(int(sys.argv[2]), sys.argv[3])
