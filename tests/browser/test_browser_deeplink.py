"""A link to an instant, in real Chromium: the address a user copies from the page (`#m=NAME&seq=N`, no
token: tokens never sit in an address) opens that machine at that instant for whoever has access, a
hash changed in the tab is followed, and the address follows a seek at once."""

from __future__ import annotations

import time

import pytest
from fsmscope.server.http_server import ServerThread
from fsmscope.server.testing.browser import PAGE_WAIT_MS
from fsmscope.server.testing.polling import wait_for
from server_support import client, two_state_machine

NAMES = ("m0", "m1")
SCREEN = {"width": 1440, "height": 900}


@pytest.fixture(scope="module")
def finished():
    """A server with two finished runs, m0 and m1, that pages look back at."""
    srv = ServerThread().start()
    for name in NAMES:
        sm = two_state_machine()
        srv.hub.add_local(sm, name=name)
        sm.execute()
    yield srv
    srv.stop()


@pytest.fixture
def context(browser):
    """A browser context of its own at 1440x900 (its own storage: a tab of another browser), closed after."""
    made = browser.new_context(viewport=SCREEN)
    yield made
    made.close()


def seqs(srv, name: str) -> list[int]:
    with client(srv) as http:
        return [e["seq"] for e in http.get("/api/machines/%s/history" % name).json()["events"]]


def link(srv, name: str, seq: int | None = None) -> str:
    """The address the page writes for ``name`` at ``seq``: the dashboard's, without its token."""
    return srv.base_url + "/#m=" + name + ("" if seq is None else "&seq=%d" % seq)


def opened(context, url: str):
    page = context.new_page()
    page.set_default_timeout(PAGE_WAIT_MS)
    page.errors = []
    page.on("pageerror", lambda e: page.errors.append(str(e)))
    page.goto(url)
    return page


def shows(page, name: str, seq: int | None) -> None:
    wait_for(lambda: page.evaluate("[window.fsmscope.name, window.fsmscope.instant.seq]") == [name, seq],
             timeout=10, what="the page to show %s at event %s" % (name, seq))


def test_a_copied_link_opened_in_a_new_tab_shows_its_instant(context, finished):
    opened(context, finished.url + "#m=m0").wait_for_selector("#badge.live")
    at = seqs(finished, "m0")[2]
    tab = opened(context, link(finished, "m0", at))
    shows(tab, "m0", at)
    assert tab.locator("#banner").is_hidden()
    assert "token" not in tab.url and not tab.errors


def test_a_link_opened_names_its_instant_all_along(context, finished):
    context.add_init_script("""window.hashes = [];
        const look = () => { window.hashes.push(location.hash); requestAnimationFrame(look); };
        requestAnimationFrame(look);""")
    at = seqs(finished, "m0")[2]
    page = opened(context, finished.url + "#m=m0&seq=%d" % at)
    shows(page, "m0", at)
    page.wait_for_timeout(500)
    assert set(page.evaluate("window.hashes")) == {"#m=m0&seq=%d" % at}


def test_a_link_opened_without_access_asks_for_the_printed_address_then_opens_its_instant(context, finished):
    at = seqs(finished, "m1")[3]
    page = opened(context, link(finished, "m1", at))
    page.wait_for_selector("#banner:has-text('Not authorized')")
    page.fill("#access input", finished.url)
    with page.expect_navigation():
        page.press("#access input", "Enter")
    shows(page, "m1", at)
    assert "token" not in page.url and not page.errors


def test_an_address_with_a_wrong_token_is_refused_and_the_link_kept(context, finished):
    page = opened(context, link(finished, "m1", 2))
    page.wait_for_selector("#banner:has-text('Not authorized')")
    page.fill("#access input", finished.base_url + "/?token=not-the-token")
    page.press("#access input", "Enter")
    page.wait_for_selector("#access .access-error:has-text('Not this server')")
    assert page.url == link(finished, "m1", 2)


def test_a_hash_changed_in_the_tab_seeks_to_its_instant(context, finished):
    first, later = seqs(finished, "m0")[1], seqs(finished, "m0")[-1]
    page = opened(context, finished.url + "#m=m0&seq=%d" % first)
    shows(page, "m0", first)
    page.evaluate("(seq) => { location.hash = 'm=m0&seq=' + seq; }", later)
    shows(page, "m0", later)


def test_a_hash_changed_in_the_tab_to_another_machine_opens_it(context, finished):
    page = opened(context, finished.url + "#m=m0")
    page.wait_for_selector("#badge.live")
    at = seqs(finished, "m1")[2]
    page.evaluate("(seq) => { location.hash = 'm=m1&seq=' + seq; }", at)
    shows(page, "m1", at)
    assert page.input_value("#machine-picker") == "m1"


def test_a_hash_without_seq_brings_a_live_machine_back_to_live(context, finished):
    at = seqs(finished, "m0")[1]
    page = opened(context, finished.url + "#m=m0&seq=%d" % at)
    page.wait_for_selector("body.looking-back")
    page.wait_for_function("(at) => location.hash === '#m=m0&seq=' + at", arg=at)
    page.evaluate("location.hash = 'm=m0'")
    page.wait_for_selector("body:not(.looking-back)")


def test_the_address_names_the_instant_within_half_a_second_of_a_seek(context, finished):
    page = opened(context, finished.url + "#m=m0")
    page.wait_for_selector("#badge.live")
    at = seqs(finished, "m0")[3]
    page.click("#log .log-row[data-seq='%d']" % at)
    shows(page, "m0", at)
    shown = time.monotonic()
    wait_for(lambda: page.evaluate("location.hash") == "#m=m0&seq=%d" % at, timeout=10,
             what="the address to name event %d" % at)
    assert time.monotonic() - shown < 0.5


def test_copy_link_copies_the_address_of_the_instant_and_says_who_it_opens_for(browser, finished):
    context = browser.new_context(viewport=SCREEN, permissions=["clipboard-read", "clipboard-write"])
    at = seqs(finished, "m1")[2]
    page = opened(context, finished.url + "#m=m1&seq=%d" % at)
    shows(page, "m1", at)
    page.click(".tl-copy")
    wait_for(lambda: page.evaluate("navigator.clipboard.readText()") == link(finished, "m1", at), timeout=5,
             what="the link in the clipboard")
    page.wait_for_selector("#notice:has-text('Link copied'):has-text('token')")
    context.close()


def test_a_seek_after_going_back_to_live_during_another_seek_is_shown(context, finished):
    s = seqs(finished, "m0")
    page = opened(context, finished.url + "#m=m0&seq=%d" % s[1])
    shows(page, "m0", s[1])
    held = []
    page.route("**/api/machines/m0/status?*", lambda route: held.append(route))  # its answer does not come yet
    page.click("#log .log-row[data-seq='%d']" % s[2])
    wait_for(lambda: held, timeout=10, what="the seek's request")
    page.click("button.tl-live")
    page.wait_for_selector("body:not(.looking-back)")
    page.unroute("**/api/machines/m0/status?*")
    page.click("#log .log-row[data-seq='%d']" % s[3])
    shows(page, "m0", s[3])
