"""What reads may cost the server (fsmscope/server/read_budget.py, fsmscope/server/read_cache.py; docs/api.md "Read budget"):
a summary or a timeline asked again with nothing new is the same answer, not worked out again; a client
that reads past its budget of the server's time is answered 429 with Retry-After, on every read route,
while another client is still served (a real uvicorn, real HTTP)."""

import secrets
from contextlib import contextmanager

import fsm
import httpx
import pytest
from fsm.logfiles.recorder import Recorder

from fsmscope.server.http_server import ServerThread
from fsmscope.server.testing.polling import wait_for
from fsmscope.server.read_budget import ReadBudget
from server_support import client
from smach_support import counting_machine

# A client's budget: 1 ms of the server's work a second, 10 ms at once; a read over it waits 0.1 s, then 429.
TIGHT = dict(rate=0.001, burst=0.01, hold=0.1)
READS = ["/api/machines/m/summary", "/api/machines/m/status?seq=5", "/api/machines/m/history?limit=10",
         "/api/machines/m/timeline", "/api/machines/m/graph.svg", "/api/machines/m/structure", "/api/machines",
         "/api/overview", "/api/machines/m/status", "/api/machines/m/breakpoints", "/api/scene", "/api/session"]
ENOUGH = 500  # reads a client asks at most before its budget must be spent


@contextmanager
def serving(tmp_path, **budget):
    """A real server showing counting_machine(20), run to its end and recorded, as 'm'."""
    srv = ServerThread(reads=ReadBudget(**budget) if budget else None).start()
    try:
        path = str(tmp_path / "m.jsonl")
        sm = counting_machine(20)
        with Recorder(path) as recorder:
            fsm.attach(sm, recorder, name="m")
            srv.hub.add_local(sm, name="m", recording=path)
            assert sm.execute() == "done"
        yield srv
    finally:
        srv.stop()


def page(srv, page_id=None):
    """An HTTP client of ``srv`` that says it is page ``page_id`` (a new one when None)."""
    http = client(srv)
    http.headers["X-Fsmscope-Page"] = page_id or secrets.token_hex(8)
    return http


def until_refused(http: httpx.Client, url: str) -> httpx.Response:
    """``url`` asked until the answer is not 200 (at most ENOUGH times): that answer."""
    for _ in range(ENOUGH):
        answer = http.get(url)
        if answer.status_code != 200:
            return answer
    raise AssertionError("%d reads of %s were all answered" % (ENOUGH, url))


@pytest.mark.parametrize("url", ["/api/machines/m/summary", "/api/machines/m/timeline"])
def test_asked_again_with_no_new_event_the_answer_is_the_same_one(tmp_path, url):
    with serving(tmp_path) as srv, client(srv) as http:
        first, again = http.get(url), http.get(url)
        assert first.status_code == again.status_code == 200, first.text
        assert first.headers["etag"] and again.headers["etag"] == first.headers["etag"]
        assert again.content == first.content


@pytest.mark.parametrize("url", ["/api/machines/m/summary", "/api/machines/m/timeline"])
def test_a_client_that_has_the_answer_is_told_it_has_not_changed(tmp_path, url):
    with serving(tmp_path) as srv, client(srv) as http:
        etag = http.get(url).headers["etag"]
        answer = http.get(url, headers={"If-None-Match": etag})
        assert answer.status_code == 304 and answer.headers["etag"] == etag and not answer.content


def test_a_new_event_makes_a_new_answer(tmp_path):
    with serving(tmp_path) as srv, client(srv) as http:
        before = http.get("/api/machines/m/summary").headers["etag"]
        srv.hub.get("m").local.reporter.send(fsm.observation.schema.build.log, "/SM_ROOT", "info", "one more")
        wait_for(lambda: http.get("/api/machines/m/summary").headers["etag"] != before,  # once delivered
                 what="a new answer after the event")


@pytest.mark.parametrize("url", READS)
def test_a_client_past_its_budget_is_answered_429_with_retry_after(tmp_path, url):
    with serving(tmp_path, **TIGHT) as srv, page(srv) as http:
        refused = until_refused(http, url)
        assert refused.status_code == 429, refused.text
        assert int(refused.headers["retry-after"]) >= 1
        detail = refused.json()["detail"]
        assert "too many reads" in detail and "retry after %s s" % refused.headers["retry-after"] in detail


def test_another_client_is_still_served(tmp_path):
    with serving(tmp_path, **TIGHT) as srv, page(srv) as greedy, page(srv) as other:
        assert until_refused(greedy, "/api/machines/m/summary").status_code == 429
        assert other.get("/api/machines/m/summary").status_code == 200
        assert greedy.get("/api/machines/m/summary").status_code == 429


def test_a_script_that_makes_up_a_new_page_for_every_read_is_bounded_all_the_same(tmp_path):
    with serving(tmp_path, **TIGHT) as srv, client(srv) as http:
        for _ in range(ENOUGH):
            answer = http.get("/api/machines/m/summary", headers={"X-Fsmscope-Page": secrets.token_hex(8)})
            if answer.status_code != 200:
                break
        assert answer.status_code == 429, answer.text


def test_a_viewer_past_its_budget_leaves_the_operator_served(tmp_path):
    with serving(tmp_path, **TIGHT) as srv, client(srv) as operator:
        viewer = httpx.Client(base_url=srv.base_url, headers={"Authorization": "Bearer " + srv.viewer_token})
        with viewer:
            for _ in range(ENOUGH):  # a script making up pages: the viewers' shared budget is spent
                answer = viewer.get("/api/machines/m/summary", headers={"X-Fsmscope-Page": secrets.token_hex(8)})
                if answer.status_code != 200:
                    break
            assert answer.status_code == 429
        assert operator.get("/api/machines/m/summary").status_code == 200
