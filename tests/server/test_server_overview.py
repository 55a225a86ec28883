"""The fleet overview's tiles (fsmscope/server/overview.py) through a real server: what each says of its
machine, and the stream that sends them, which takes the token as every stream does."""

from __future__ import annotations

import json
import threading

import fsm
import pytest
from event_support import ev, flat_root, run_of
from server_support import client
from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect

from fsm.observation import schema
from fsmscope.server.testing.polling import wait_for


def tiles(srv) -> dict[str, dict]:
    with client(srv) as http:
        return {t["name"]: t for t in http.get("/api/overview").raise_for_status().json()}


def test_a_local_machines_tile_says_it_runs_in_which_state_then_how_it_ended(live_server):
    gate = threading.Event()

    def wait(ud):
        gate.wait(10)
        return "go"

    sm = fsm.StateMachine(["done"])
    with sm:
        fsm.StateMachine.add("WAIT", fsm.CBState(wait, outcomes=["go"]), {"go": "done"})
    live_server.hub.add_local(sm, name="m")
    runner = threading.Thread(target=sm.execute)
    runner.start()
    wait_for(lambda: tiles(live_server)["m"]["state"] == "running", 5, what="m running")
    tile = tiles(live_server)["m"]
    assert (tile["robot"], tile["machine"], tile["source"], tile["active"]) == (None, "m", "local", ["/SM_ROOT/WAIT"])
    gate.set()
    runner.join(5)
    tile = tiles(live_server)["m"]
    assert (tile["state"], tile["outcome"], tile["active"], tile["connected"]) == ("done", "done", [], True)
    assert tile["last_seen"] is not None and tile["last_seq"] > 0


def ingest(srv, name: str, events: list[dict]) -> None:
    """Events of another process's machine ``name``, as its publisher sends them."""
    for event in events:
        assert srv.hub.ingest(dict(event, machine=name)) is None


def started(name: str) -> list[dict]:
    """Its structure (one state, A) and its start."""
    return run_of(flat_root("A"), name)[:2]


def test_a_run_that_failed_stays_failed_when_its_process_goes(live_server):
    ingest(live_server, "r2:pick", started("r2:pick") + [
        ev(3, "error", machine="r2:pick", state="A", exc_type="RuntimeError", message="jammed"),
        ev(4, "terminate", machine="r2:pick", last=["A"], state_outcome=None, outcome=None, active=[],
           error="RuntimeError: jammed")])
    live_server.hub.get("r2:pick").origin.connected = False
    live_server.hub.get("r2:pick").origin.robot = "r2"
    tile = tiles(live_server)["r2:pick"]
    assert (tile["state"], tile["error"], tile["connected"], tile["robot"], tile["machine"]) == (
        "failed", "RuntimeError", False, "r2", "pick")


def test_a_running_machine_whose_process_goes_is_gone(live_server):
    ingest(live_server, "r3:patrol", started("r3:patrol"))
    assert tiles(live_server)["r3:patrol"]["state"] == "running"
    live_server.hub.get("r3:patrol").origin.connected = False
    assert tiles(live_server)["r3:patrol"]["state"] == "gone"


def test_the_overview_stream_sends_the_tiles(live_server):
    ingest(live_server, "r3:patrol", started("r3:patrol"))
    url = "ws://127.0.0.1:%d/api/overview/stream?token=%s" % (live_server.port, live_server.token)
    with connect(url, open_timeout=5) as ws:
        frame = json.loads(ws.recv(timeout=5))
    assert frame["type"] == "overview" and [t["name"] for t in frame["tiles"]] == ["r3:patrol"]


def test_the_overview_frame_and_its_tiles_fit_the_schema(live_server):
    ingest(live_server, "r4:sort", started("r4:sort"))
    url = "ws://127.0.0.1:%d/api/overview/stream?token=%s" % (live_server.port, live_server.token)
    with connect(url, open_timeout=5) as ws:
        frame = json.loads(ws.recv(timeout=5))
    assert schema.frame_problem(frame) is None
    assert [set(t) for t in frame["tiles"]] == [{f.name for f in schema.TILE_FIELDS}]


def test_the_overview_stream_refuses_a_client_without_the_token(live_server):
    with pytest.raises(InvalidStatus) as info:
        connect("ws://127.0.0.1:%d/api/overview/stream" % live_server.port, open_timeout=5)
    assert info.value.response.status_code == 401
