"""Property: ill-typed and hostile events of every kind, fed through every door (the server's
ingest, `fsmscope replay`, `fsmscope replay --serve`), never raise, never answer 5xx, and leave
every endpoint answering for every machine."""

from __future__ import annotations

import json

import httpx
import pytest
from hypothesis import HealthCheck, given, settings, strategies as st
from websockets.sync.client import connect

from event_support import ev, flat_root, run_of
from recording_support import replay_served
from fsmscope.server import cli
from server_support import client, frames, stream

# Values an attacker or a broken publisher might put anywhere.
NASTY = st.sampled_from([None, True, 0, -1, 2 ** 53, 2 ** 70, 1.5, -1e308, "", "x" * 5000, "VT\x0bBAD",
                         "<img src=x onerror=alert(1)>", "../../etc/passwd", "\u202eevil", [], {}, [[[[[[]]]]]],
                         {"__proto__": {"polluted": 1}}])
JSON = st.recursive(st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False, allow_infinity=False)
                    | st.text(max_size=20) | NASTY,
                    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=8), inner, max_size=4),
                    max_leaves=12)


def deeply_nested(depth: int) -> list:
    value: list = []
    for _ in range(depth):
        value = [value]
    return value


def templates(machine: str) -> list[dict]:
    """One valid event of every kind (the run's, plus the kinds a run does not show)."""
    run = run_of(flat_root("A", "B"), machine=machine)
    status = {"containers": {"/SM_ROOT": {"active": [], "initial": ["A"], "userdata": {}, "running": False,
                                          "outcome": "done"}}, "running": False, "outcome": "done",
              "structure": flat_root("A", "B"), "root_path": "/SM_ROOT", "last_seq": 9}
    return run + [ev(10, "userdata", machine=machine, changes={"k": 1}),
                  ev(11, "preempt", machine=machine, phase="requested"),
                  ev(12, "error", machine=machine, state="A", exc_type="ValueError", message="boom"),
                  ev(13, "log", machine=machine, level="warn", msg="careful"),
                  ev(14, "feedback", machine=machine, path="/SM_ROOT/A", action="move", feedback={"d": 1}),
                  ev(15, "control", machine=machine, action="preempt", client="x", result="accepted"),
                  ev(16, "transition", machine=machine, changes={"k": 2},
                     **{"from": "A", "outcome": "go", "to": "B", "active": ["B"]}),
                  ev(17, "snapshot", machine=machine, status=status)]


@st.composite
def hostile(draw, machine: str = "m") -> dict:
    """A valid event of a random kind with one to three of its fields (or of its nested objects)
    replaced by something else, deleted, or nested past every limit."""
    event = json.loads(json.dumps(draw(st.sampled_from(templates(machine)))))
    for _ in range(draw(st.integers(1, 3))):
        target = event
        while True:  # walk down into nested objects now and then
            keys = list(target) if isinstance(target, dict) else list(range(len(target)))
            if not keys:
                break
            key = draw(st.sampled_from(keys))
            if isinstance(target[key], (dict, list)) and target[key] and draw(st.booleans()):
                target = target[key]
                continue
            break
        if not keys:
            continue
        action = draw(st.sampled_from(["replace", "delete", "deep"]))
        if action == "delete":
            del target[key]
        elif action == "deep":
            target[key] = deeply_nested(draw(st.integers(30, 400)))
        else:
            target[key] = draw(JSON)
    return event


def endpoints_answer(base_url: str, token: str) -> None:
    """Every endpoint answers every machine without a server error."""
    http = httpx.Client(base_url=base_url, headers={"Authorization": "Bearer " + token}, timeout=10)
    machines = http.get("/api/machines")
    assert machines.status_code == 200, machines.text
    for info in machines.json():
        name = info["name"]
        for path in ("/status", "/structure", "/graph.svg", "/timeline"):
            answer = http.get("/api/machines/%s%s" % (name, path))
            assert answer.status_code < 500, (name, path, answer.status_code, answer.text)


@pytest.fixture(scope="module")
def server():
    from fsmscope.server.http_server import ServerThread

    srv = ServerThread().start()
    yield srv
    srv.stop()


@settings(max_examples=60, deadline=None, suppress_health_check=list(HealthCheck), database=None)
@given(events=st.lists(hostile(), min_size=1, max_size=6))
def test_hostile_events_through_ingest_leave_every_endpoint_and_the_stream_working(server, events):
    url = "ws://127.0.0.1:%d/api/ingest?token=%s" % (server.port, server.token)
    with connect(url, compression=None, open_timeout=5) as ws:
        ws.send(json.dumps(run_of(flat_root("A", "B")) + events))
        ws.send(json.dumps([ev(10 ** 6, "log", level="info", msg="sentinel")]))
        sentinel = {"v": 1}
        ws.send(json.dumps([sentinel]))  # refused: its answer comes after every earlier event's
        while json.loads(ws.recv(timeout=10))["machine"] is not None:
            pass
    endpoints_answer(server.base_url, server.token)
    for info in client(server).get("/api/machines").json():
        with stream(server, info["name"]) as sock:
            assert frames(sock, lambda got: len(got) == 1)[0]["type"] in ("snapshot", "events")


@settings(max_examples=100, deadline=None, suppress_health_check=list(HealthCheck), database=None)
@given(events=st.lists(hostile(), min_size=1, max_size=6))
def test_hostile_events_in_a_log_never_break_headless_replay(tmp_path_factory, events, capsys):
    log = tmp_path_factory.mktemp("hostile") / "run.jsonl"
    log.write_text("\n".join(json.dumps(e) for e in run_of(flat_root("A", "B")) + events) + "\n")
    assert cli.main(["replay", str(log), "--no-time"]) in (0, 1, 2)  # 2: a line of a newer schema version
    assert cli.main(["replay", str(log), "--json"]) in (0, 1, 2)
    assert "Traceback" not in capsys.readouterr().err


@settings(max_examples=6, deadline=None, suppress_health_check=list(HealthCheck), database=None)
@given(events=st.lists(hostile(), min_size=3, max_size=10))
def test_hostile_events_in_a_log_never_break_replay_in_the_dashboard(tmp_path_factory, events):
    # A line of a newer schema version ends any replay on purpose (exit 2; tests/unit/test_log_reader.py).
    events = [e for e in events if not (type(e.get("v")) is int and e["v"] > 1)]
    log = tmp_path_factory.mktemp("hostile") / "run.jsonl"
    log.write_text("\n".join(json.dumps(e) for e in run_of(flat_root("A", "B")) + events) + "\n")
    with replay_served(log, "--token", "hostile-token") as (url, _):
        endpoints_answer(url.split("/?")[0], "hostile-token")
