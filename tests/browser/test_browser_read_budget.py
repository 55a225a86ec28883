"""A page whose read is refused for the budget of the server's time (429, fsmscope/server/read_budget.py) waits the
Retry-After it is told and asks again (fsmscope/static/api.js): the page gets its answer, not an error."""

from __future__ import annotations

import secrets

import httpx

from browser_support import watching
from fsmscope.server.http_server import ServerThread
from fsmscope.server.read_budget import ReadBudget
from server_support import two_state_machine

# Once the page is open: an address's clients share 4 x 0.02 s of the server's work at once, refilled at
# 4 x 0.2 % of a core; a read over it waits 0.1 s, then 429.
TIGHT = dict(rate=0.002, burst=0.02, hold=0.1)
ASK_SUMMARY = "async () => (await import('/api.js')).api.summary('two')"


def spend_the_address_budget(srv: ServerThread) -> None:
    """Read as a script that makes up a page per read until the address's shared budget is spent (429)."""
    with httpx.Client(base_url=srv.base_url, headers={"Authorization": "Bearer " + srv.token}, timeout=10) as http:
        for _ in range(1000):
            answer = http.get("/api/machines/two/summary", headers={"X-Fsmscope-Page": secrets.token_hex(8)})
            if answer.status_code == 429:
                return
    raise AssertionError("1000 reads did not spend the budget")


def test_a_read_refused_for_the_budget_is_asked_again_after_its_retry_after(browser):
    srv = ServerThread().start()
    sm = two_state_machine()
    srv.hub.add_local(sm, name="two")
    try:
        assert sm.execute() == "done"
        with watching(browser, srv, "two") as page:
            srv.app.state.reads = ReadBudget(**TIGHT)
            spend_the_address_budget(srv)
            answer = page.evaluate(ASK_SUMMARY)
            assert set(answer["states"]) == {"/SM_ROOT/FOO", "/SM_ROOT/BAR"}
    finally:
        srv.stop()
