"""Events from another process are checked at the door (/api/ingest): an ill-typed one is refused
with its reason, counted on its machine, and never reaches the Status, the graph or a client."""

from __future__ import annotations

import json
import time

import pytest
from websockets.sync.client import connect

from event_support import deep_root, ev, flat_root, run_of
from fsmscope.server.testing.polling import wait_for
from server_support import client, frames, stream


@pytest.fixture
def ingest(live_server):
    url = "ws://127.0.0.1:%d/api/ingest?token=%s" % (live_server.port, live_server.token)
    with connect(url, compression=None, open_timeout=5) as ws:
        yield ws


def send(ws, *events) -> None:
    ws.send(json.dumps(list(events)))


def machine_info(srv, name="m") -> dict:
    answer = client(srv).get("/api/machines")
    assert answer.status_code == 200, answer.text
    return {m["name"]: m for m in answer.json()}[name]


def fed_run(srv, ws, *extra) -> None:
    """A valid run of m, then ``extra`` events, then wait until the server has the valid ones."""
    run = run_of(flat_root("A", "B"))
    send(ws, *run, *extra)
    wait_for(lambda: machine_info(srv)["last_seq"] == run[-1]["seq"])


def test_an_ill_typed_terminate_is_refused_and_the_machine_list_keeps_answering(live_server, ingest):
    bad = ev(9, "terminate", last=["B"], outcome=5)
    fed_run(live_server, ingest, bad)
    rejected = json.loads(ingest.recv(timeout=5))
    assert rejected == {"type": "rejected", "reason": "terminate.outcome must be a string or null, not an integer",
                        "machine": "m", "seq": 9}
    info = machine_info(live_server)
    assert info["outcome"] == "done" and info["rejected"] == 1


def test_a_time_that_is_not_a_number_is_refused_and_status_keeps_answering(live_server, ingest):
    bad = ev(9, "log", level="info", msg="hi")
    bad["t"] = "yesterday"
    fed_run(live_server, ingest, bad)
    assert json.loads(ingest.recv(timeout=5))["type"] == "rejected"
    answer = client(live_server).get("/api/machines/m/status")
    assert answer.status_code == 200 and answer.json()["last_t"] == 1000.0 + answer.json()["last_seq"]


def test_a_malformed_structure_is_refused_and_structure_and_graph_keep_answering(live_server, ingest):
    broken = flat_root("A", "B")
    del broken["children"][1]["outcomes"]
    fed_run(live_server, ingest, ev(9, "structure", root=broken))
    assert "lacks 'outcomes'" in json.loads(ingest.recv(timeout=5))["reason"]
    http = client(live_server)
    assert [c["label"] for c in http.get("/api/machines/m/structure").json()["children"]] == ["A", "B"]
    assert http.get("/api/machines/m/graph.svg").status_code == 200


def test_a_structure_200_levels_deep_is_refused_and_the_stream_keeps_working(live_server, ingest):
    fed_run(live_server, ingest, ev(9, "structure", root=deep_root(200)))
    assert "deeper than" in json.loads(ingest.recv(timeout=5))["reason"]
    assert client(live_server).get("/api/machines/m/graph.svg").status_code == 200
    with stream(live_server, "m") as ws:
        [snap] = frames(ws, lambda got: len(got) == 1)
        assert snap["type"] == "snapshot" and snap["status"]["outcome"] == "done"
        send(ingest, ev(9, "log", level="info", msg="still here"))
        [more] = frames(ws, lambda got: len(got) == 1)
    assert more["events"][0]["msg"] == "still here"


def test_a_refused_event_never_reaches_a_client(live_server, ingest):
    fed_run(live_server, ingest)
    with stream(live_server, "m") as ws:
        frames(ws, lambda got: len(got) == 1)
        send(ingest, ev(9, "terminate", last=["B"], outcome=5), ev(10, "log", level="info", msg="after"))
        got = frames(ws, lambda got: any(f["type"] == "events" for f in got))
    assert [e["seq"] for f in got for e in f.get("events", [])] == [10]


def test_a_frame_that_is_not_json_closes_the_publisher_with_1007(live_server, ingest):
    ingest.send("not json")
    with pytest.raises(Exception):
        ingest.recv(timeout=5)
    assert ingest.close_code == 1007


def test_an_event_naming_no_machine_is_refused_without_creating_one(live_server, ingest):
    send(ingest, {"v": 1, "seq": 1, "t": time.time(), "kind": "log", "path": "/SM_ROOT", "level": "info",
                  "msg": "who am I"})
    assert json.loads(ingest.recv(timeout=5))["reason"] == "event lacks 'machine'"
    assert client(live_server).get("/api/machines").json() == []
