"""REST API against a real uvicorn on a free port, with real fsm machines (docs/api.md)."""

import threading
import time
import xml.etree.ElementTree as ET

import fsm
import httpx
from fsm.control.handle import CANNOT_HOLD
from fsm.ros.bus import default_bus

from fsmscope.server.testing.polling import wait_for
from server_support import client, nested_machine, two_state_machine, waiting_machine


def run_in_thread(sm):
    result = {}
    thread = threading.Thread(target=lambda: result.setdefault("outcome", sm.execute()), daemon=True)
    thread.start()
    return thread, result


def test_health_needs_no_token(live_server):
    assert httpx.get(live_server.base_url + "/api/health").json() == {"ok": True}


def test_api_without_token_is_401_with_json_detail(live_server):
    answer = client(live_server, token=False).get("/api/machines")
    assert answer.status_code == 401 and isinstance(answer.json()["detail"], str)


def test_wrong_token_is_401(live_server):
    answer = httpx.get(live_server.base_url + "/api/machines", headers={"Authorization": "Bearer nope"})
    assert answer.status_code == 401


def test_foreign_host_header_is_400(live_server):
    answer = client(live_server).get("/api/health", headers={"Host": "evil.example:%d" % live_server.port})
    assert answer.status_code == 400


def test_docs_page_loads_swagger_ui_from_this_server_not_a_cdn(live_server):
    page = httpx.get(live_server.base_url + "/docs")
    assert page.status_code == 200
    assert "https://" not in page.text and "/docs-assets/swagger-ui-bundle.js" in page.text
    assert httpx.get(live_server.base_url + "/docs-assets/swagger-ui-bundle.js").status_code == 200


def test_pages_may_not_be_framed_by_other_sites(live_server):
    headers = httpx.get(live_server.base_url + "/").headers
    assert headers["x-frame-options"] == "DENY"
    assert headers["content-security-policy"] == "frame-ancestors 'none'"


def test_lists_machines(live_server):
    live_server.hub.add_local(two_state_machine(), name="two")
    [info] = client(live_server).get("/api/machines").json()
    assert info == {"name": "two", "running": False, "outcome": None, "last_seq": 0, "root_path": "/SM_ROOT",
                    "can_start": True, "can_hold": False, "held": False, "cannot": {"hold": CANNOT_HOLD},
                    "source": "local", "controllable": True, "connected": None, "rejected": 0, "replay": None,
                    "script": None}


def test_structure_and_status_after_a_run(live_server):
    sm = two_state_machine()
    live_server.hub.add_local(sm, name="two")
    assert sm.execute() == "done"
    http = client(live_server)
    assert [c["label"] for c in http.get("/api/machines/two/structure").json()["children"]] == ["FOO", "BAR"]
    status = http.get("/api/machines/two/status").json()
    assert status["outcome"] == "done" and "structure" not in status
    assert status["containers"]["/SM_ROOT"]["userdata"] == {"visits": ["FOO", "BAR"]}


def test_the_status_says_where_a_debugged_machine_holds_and_why(live_server):
    from fsm.debugging import Debugger

    sm = two_state_machine()
    live_server.hub.add_local(sm, name="two")
    debugger = Debugger(sm)
    debugger.set_breakpoints([{"state": "/SM_ROOT/BAR", "at": "before", "when": "len(visits) == 1"}])
    thread, result = run_in_thread(sm)
    try:
        http = client(live_server)
        wait_for(lambda: http.get("/api/machines/two/status").json()["debug"]["holds"])
        debug = http.get("/api/machines/two/status").json()["debug"]
        assert debug["mode"] == "pause"
        assert [(h["state"], h["at"], h["detail"]) for h in debug["holds"]] == [
            ("BAR", "before", "hit breakpoint before BAR when len(visits) == 1")]
        assert debug["breakpoints"] == [{"state": "/SM_ROOT/BAR", "at": "before", "outcome": None,
                                         "when": "len(visits) == 1"}]
    finally:
        debugger.detach()
        thread.join(5)
    assert result["outcome"] == "done"


def test_unknown_machine_is_404(live_server):
    assert client(live_server).get("/api/machines/nope/status").status_code == 404


def test_preempt_of_a_running_machine_ends_it_preempted(live_server):
    sm, wait = waiting_machine()
    live_server.hub.add_local(sm, name="w")
    thread, result = run_in_thread(sm)
    assert wait.entered.wait(5)
    answer = client(live_server).post("/api/machines/w/preempt", json={"reason": "operator"})
    assert answer.status_code == 202 and answer.json()["seq"] > 0
    thread.join(5)
    assert result["outcome"] == "preempted"


def test_preempt_of_a_finished_machine_is_409(live_server):
    sm = two_state_machine()
    live_server.hub.add_local(sm, name="two")
    sm.execute()
    assert client(live_server).post("/api/machines/two/preempt", json={}).status_code == 409


def test_initial_state_then_start_runs_from_that_state_with_that_userdata(live_server):
    sm = two_state_machine()
    live_server.hub.add_local(sm, name="two")
    http = client(live_server)
    answer = http.post("/api/machines/two/initial-state", json={"states": ["BAR"], "userdata": {"visits": ["X"]}})
    assert answer.status_code == 200
    assert http.post("/api/machines/two/start", json={}).status_code == 202
    wait_for(lambda: http.get("/api/machines/two/status").json()["outcome"] == "done")
    assert http.get("/api/machines/two/status").json()["containers"]["/SM_ROOT"]["userdata"] == \
        {"visits": ["X", "BAR"]}


def test_initial_state_with_an_unknown_state_is_422(live_server):
    live_server.hub.add_local(two_state_machine(), name="two")
    assert client(live_server).post("/api/machines/two/initial-state", json={"states": ["NOPE"]}).status_code == 422


def test_initial_state_of_a_concurrence_is_422(live_server):
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        cc = fsm.Concurrence(outcomes=["done"], default_outcome="done")
        with cc:
            fsm.Concurrence.add("A", fsm.CBState(lambda ud: "go", outcomes=["go"]))
        fsm.StateMachine.add("CC", cc, {"done": "done"})
    live_server.hub.add_local(sm, name="cc")
    answer = client(live_server).post("/api/machines/cc/initial-state", json={"path": "/SM_ROOT/CC", "states": ["A"]})
    assert answer.status_code == 422


def test_initial_state_at_an_unknown_path_is_404(live_server):
    live_server.hub.add_local(two_state_machine(), name="two")
    answer = client(live_server).post("/api/machines/two/initial-state", json={"path": "/SM_ROOT/X", "states": []})
    assert answer.status_code == 404


def test_start_while_running_is_409(live_server):
    sm, wait = waiting_machine()
    live_server.hub.add_local(sm, name="w")
    thread, _ = run_in_thread(sm)
    assert wait.entered.wait(5)
    try:
        assert client(live_server).post("/api/machines/w/start", json={}).status_code == 409
    finally:
        wait.release.set()
        thread.join(5)


def test_start_of_a_machine_this_process_cannot_rerun_is_409(live_server):
    live_server.hub.add_local(two_state_machine(), name="two", can_start=False)
    assert client(live_server).post("/api/machines/two/start", json={}).status_code == 409


def test_body_over_64_kib_is_413(live_server):
    answer = client(live_server).post("/api/topics/big", content=b"[" + b"1," * 40000 + b"1]",
                                      headers={"Content-Type": "application/json"})
    assert answer.status_code == 413


def test_invalid_body_is_422_with_a_text_detail(live_server):
    live_server.hub.add_local(two_state_machine(), name="two")
    answer = client(live_server).post("/api/machines/two/initial-state", json={"states": "BAR"})
    assert answer.status_code == 422 and isinstance(answer.json()["detail"], str)


def test_a_cookie_holding_the_token_does_not_authorize(live_server):
    live_server.hub.add_local(two_state_machine(), name="two")
    answer = httpx.get(live_server.base_url + "/api/machines", cookies={"fsmscope_token": live_server.token})
    assert answer.status_code == 401


def test_a_foreign_origin_cannot_post_even_with_the_token(live_server):
    live_server.hub.add_local(two_state_machine(), name="two")
    answer = client(live_server).post("/api/machines/two/start", json={}, headers={"Origin": "http://evil.example"})
    assert answer.status_code == 403


def test_the_page_is_served_without_setting_a_cookie(live_server):
    answer = httpx.get(live_server.base_url + "/?token=" + live_server.token)
    assert answer.status_code == 200 and "set-cookie" not in answer.headers
    assert "<title>fsmscope</title>" in answer.text


def test_topic_publish_reaches_subscribers(live_server):
    got = []
    sub = default_bus.subscribe("test_topic_publish", got.append)
    try:
        answer = client(live_server).post("/api/topics/test_topic_publish", json={"stop": True})
    finally:
        sub.unregister()
    assert answer.status_code == 202 and answer.json() == {"delivered": 1} and got == [{"stop": True}]


def test_control_requests_become_control_events(live_server):
    sm = two_state_machine()
    entry = live_server.hub.add_local(sm, name="two")
    client(live_server).post("/api/machines/two/preempt", json={"reason": "why not"})
    wait_for(lambda: any(seq for seq, _ in entry.feed.ring))
    import json
    [event] = [json.loads(enc) for _, enc in entry.feed.ring]
    assert (event["kind"], event["action"], event["reason"], event["result"], event["client"]) == \
        ("control", "preempt", "why not", "not running", "127.0.0.1 (operator)")


def test_graph_svg_has_the_documented_ids(live_server):
    live_server.hub.add_local(nested_machine(), name="n")
    answer = client(live_server).get("/api/machines/n/graph.svg")
    assert answer.headers["content-type"].startswith("image/svg+xml")
    ids = {el.get("id") for el in ET.fromstring(answer.content).iter() if el.get("id")}
    assert {"c:/SM_ROOT", "c:/SM_ROOT/SUB", "s:/SM_ROOT/SUB/A", "s:/SM_ROOT/C", "o:/SM_ROOT:done",
            "e:/SM_ROOT/SUB:A:go", "e:/SM_ROOT:SUB:done"} <= ids


def test_graph_svg_draws_an_unexpanded_container_as_one_node(live_server):
    live_server.hub.add_local(nested_machine(), name="n")
    answer = client(live_server).get("/api/machines/n/graph.svg", params={"expand": "/SM_ROOT"})
    ids = {el.get("id") for el in ET.fromstring(answer.content).iter() if el.get("id")}
    assert "s:/SM_ROOT/SUB" in ids and "c:/SM_ROOT/SUB" not in ids and "s:/SM_ROOT/SUB/A" not in ids


def test_graph_of_an_unknown_expand_path_is_404(live_server):
    live_server.hub.add_local(nested_machine(), name="n")
    assert client(live_server).get("/api/machines/n/graph.svg", params={"expand": "/X"}).status_code == 404


def test_start_with_a_starter_calls_it_in_a_worker_thread_instead_of_running_the_machine(live_server):
    calls = []
    sm = two_state_machine()
    entry = live_server.hub.add_local(sm, name="hosted", starter=lambda: calls.append(threading.get_ident()))
    answer = client(live_server).post("/api/machines/hosted/start", json={})
    assert answer.status_code == 202
    assert len(calls) == 1 and calls[0] not in (live_server._thread.ident, threading.get_ident())
    assert entry.local.handle._thread is None and entry.local.reporter.run is None  # the hub did not execute it


def test_a_failing_starter_answers_409_with_its_message(live_server):
    def starter():
        raise RuntimeError("no episode")
    live_server.hub.add_local(two_state_machine(), name="hosted", starter=starter)
    answer = client(live_server).post("/api/machines/hosted/start", json={})
    assert answer.status_code == 409 and "no episode" in answer.json()["detail"]


def test_start_right_after_the_outcome_is_out_runs_again(live_server):
    """A page may ask for the next run as soon as it sees the outcome, a moment before the last
    run's execute() has returned (here a termination callback still runs): that is not a 409."""
    sm = two_state_machine()
    sm.register_termination_cb(lambda ud, states, outcome: time.sleep(0.3))
    live_server.hub.add_local(sm, name="two")
    http = client(live_server)
    assert http.post("/api/machines/two/start", json={}).status_code == 202
    wait_for(lambda: http.get("/api/machines/two/status").json()["outcome"] == "done")
    assert http.post("/api/machines/two/start", json={}).status_code == 202
