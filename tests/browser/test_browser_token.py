"""The dashboard's token stays with its own server: no other server on the same host ever receives
it, and two dashboards on two ports in one browser both keep working (cookies would fail both:
they are not port-scoped)."""

from __future__ import annotations

import http.server
import threading

import pytest

from fsmscope.server.http_server import ServerThread
from fsmscope.server.testing.browser import PAGE_WAIT_MS
from server_support import two_state_machine


class Capture(http.server.BaseHTTPRequestHandler):
    """Another local web server: answers every GET and keeps the headers it was sent."""

    seen: list[dict] = []

    def do_GET(self) -> None:
        Capture.seen.append(dict(self.headers))
        body = b"<!doctype html><title>other</title><p>another server"
        self.send_response(200)
        self.send_header("Content-Type", "text/html")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args) -> None:
        pass


@pytest.fixture
def other_server():
    Capture.seen = []
    srv = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Capture)
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    yield "http://127.0.0.1:%d/" % srv.server_address[1]
    srv.shutdown()
    srv.server_close()


@pytest.fixture
def two_dashboards():
    servers = [ServerThread().start() for _ in range(2)]
    for i, srv in enumerate(servers):
        srv.hub.add_local(two_state_machine(), name="m%d" % i)
    yield servers
    for srv in servers:
        srv.stop()


def open_dashboard(context, srv):
    page = context.new_page()
    page.set_default_timeout(PAGE_WAIT_MS)
    page.goto(srv.url)
    page.wait_for_selector("#badge.live")
    return page


def test_no_other_server_on_the_host_receives_the_token(browser, two_dashboards, other_server):  # noqa: F811
    srv = two_dashboards[0]
    context = browser.new_context()
    open_dashboard(context, srv)
    other = context.new_page()
    other.goto(other_server)
    other.reload()
    context.close()
    assert Capture.seen, "the other server was not visited"
    assert not any(srv.token in value for headers in Capture.seen for value in headers.values())


def test_the_token_leaves_the_address_bar_and_survives_a_reload(browser, two_dashboards):  # noqa: F811
    srv = two_dashboards[0]
    context = browser.new_context()
    page = open_dashboard(context, srv)
    assert "token" not in page.url
    page.reload()
    page.wait_for_selector("#badge.live")
    assert page.input_value("#machine-picker") == "m0"
    context.close()


def test_two_dashboards_on_two_ports_in_one_browser_both_keep_working(browser, two_dashboards):  # noqa: F811
    context = browser.new_context()
    first = open_dashboard(context, two_dashboards[0])
    second = open_dashboard(context, two_dashboards[1])
    for page, name in ((first, "m0"), (second, "m1")):
        page.reload()
        page.wait_for_selector("#badge.live")
        page.click("#start-btn")
        page.wait_for_function("document.querySelector('#run-state').textContent.startsWith('finished')")
        assert page.input_value("#machine-picker") == name
    assert not first.locator("#banner").is_visible() and not second.locator("#banner").is_visible()
    context.close()
