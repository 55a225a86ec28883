"""`--foxglove`'s door (fsmscope/interop/foxglove_door.py) in real Chromium: a page of another site, or a
local file's page, cannot read a machine's events from the Foxglove server, neither through its
port nor through the SDK's inner one; a page of Foxglove's web app can, and so can a file's page
once the user allowed the origin ``null``."""

from __future__ import annotations

import threading

import fsm
import pytest

from fsmscope.interop.foxglove_door import Admission
from fsmscope.interop.foxglove_live import FoxgloveLive
from fsmscope.server.testing.browser import PAGE_WAIT_MS

# What a page can read: the first event of the machine's events channel, or why it read none.
READ_AN_EVENT = """([url, topic]) => new Promise(resolve => {
  let ws;
  try { ws = new WebSocket(url, ["foxglove.sdk.v1"]); } catch (e) { resolve("refused: " + e.name); return; }
  ws.binaryType = "arraybuffer";
  ws.onmessage = (m) => {
    if (typeof m.data !== "string") {  // MessageData: op, subscription, log time, the event
      resolve("read: " + new TextDecoder().decode(new Uint8Array(m.data).slice(13)));
      return;
    }
    const frame = JSON.parse(m.data);
    const channel = frame.op === "advertise" && frame.channels.find(c => c.topic === topic);
    if (channel) ws.send(JSON.stringify({op: "subscribe", subscriptions: [{id: 1, channelId: channel.id}]}));
  };
  ws.onerror = () => resolve("refused");
  setTimeout(() => resolve("nothing read"), 8000);
})"""
TOPIC = "/fsmscope/loop/events"


def looping(stop: threading.Event) -> fsm.StateMachine:
    """A machine that goes A -> B -> A ... every 10 ms until ``stop`` is set."""
    sm = fsm.StateMachine(["done"])

    def tick(ud):
        return "stop" if stop.wait(0.01) else "go"
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(tick, outcomes=["go", "stop"]), {"go": "B", "stop": "done"})
        fsm.StateMachine.add("B", fsm.CBState(tick, outcomes=["go", "stop"]), {"go": "A", "stop": "done"})
    return sm


@pytest.fixture
def serving():
    """A Foxglove server, with the admission a test gives it, fed by a machine that runs until the test ends."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    stop = threading.Event()
    started = []

    def start(admission: Admission = Admission()) -> FoxgloveLive:
        live = FoxgloveLive(port=0, admission=admission)
        sm = looping(stop)
        fsm.attach(sm, live.event, name="loop")
        runner = threading.Thread(target=sm.execute, daemon=True)
        runner.start()
        started.append((live, runner))
        return live
    yield start
    stop.set()
    for live, runner in started:
        runner.join(10)
        live.stop()


def page_of(browser, url: str, tmp_path=None):
    """A page at ``url``: a site's address (answered here, the network never asked), or a file's. The
    page may reach the loopback, as one whose user allowed it (Chromium asks the user first: Local
    Network Access), so that the door, not the browser, is what any refusal comes from."""
    page = browser.new_context(permissions=["local-network-access"]).new_page()
    page.set_default_timeout(PAGE_WAIT_MS)
    if url.startswith("file:"):
        path = tmp_path / "page.html"
        path.write_text("<!doctype html><title>a local file</title>")
        url = path.as_uri()
    else:
        page.route(url + "**", lambda route: route.fulfill(body="<!doctype html><title>a site</title>",
                                                           content_type="text/html"))
    page.goto(url)
    return page


def what_a_page_reads(browser, url: str, server_url: str, tmp_path=None) -> str:
    page = page_of(browser, url, tmp_path)
    try:
        return page.evaluate(READ_AN_EVENT, [server_url, TOPIC])
    finally:
        page.context.close()


def test_a_page_of_foxglove_s_web_app_reads_the_events(browser, serving):
    live = serving()
    assert what_a_page_reads(browser, "https://app.foxglove.dev/", "ws://127.0.0.1:%d" % live.port).startswith("read:")


def test_a_page_of_another_site_reads_nothing(browser, serving):
    live = serving()
    for site in ("https://evil.example/", "http://localhost:1/"):
        assert not what_a_page_reads(browser, site, "ws://127.0.0.1:%d" % live.port).startswith("read:"), site


def test_a_local_file_s_page_reads_nothing(browser, serving, tmp_path):
    live = serving()
    assert not what_a_page_reads(browser, "file:", "ws://127.0.0.1:%d" % live.port, tmp_path).startswith("read:")


def test_no_page_reads_from_the_inner_port_even_foxglove_s(browser, serving):
    live = serving()
    for scheme in ("ws", "wss"):
        inner = "%s://127.0.0.1:%d" % (scheme, live.door.inner_port)
        got = what_a_page_reads(browser, "https://app.foxglove.dev/", inner)
        assert not got.startswith("read:"), scheme


def test_a_local_file_s_page_reads_the_events_once_the_user_allowed_its_origin(browser, serving, tmp_path):
    live = serving(Admission.allowing(origins=["null"]))
    assert what_a_page_reads(browser, "file:", "ws://127.0.0.1:%d" % live.port, tmp_path).startswith("read:")
