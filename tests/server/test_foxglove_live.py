"""`--foxglove PORT`: a Foxglove client (a real websocket, Foxglove's subprotocol) connected to the
foxglove-sdk server that the hub feeds sees the machine's channels and its active state change; so
does one connected to a command that serves no dashboard (`run --no-serve`, `demo --headless`)."""

from __future__ import annotations

import argparse
import asyncio
import concurrent.futures
import contextlib
import json
import os
import queue
import re
import signal
import socket
import subprocess
import sys
import threading
import time

import fsm
import pytest
import websockets
from recording_support import two_state_loop

from recording_support import ROOT
from fsmscope.server.cli.foxglove_bridge import start_foxglove
from fsmscope.server.http_server import ServerThread

SUBPROTOCOL = "foxglove.sdk.v1"


def foxglove_args(host: str = "127.0.0.1", **options) -> argparse.Namespace:
    """The command line's options of ``--foxglove 0`` (``foxglove_origin``, ``foxglove_host``: lists)."""
    return argparse.Namespace(**{"host": host, "foxglove": 0, "foxglove_origin": None, "foxglove_host": None,
                                 **options})


async def watch(port: int, topic: str, started: threading.Event, want: int) -> tuple[dict, list[dict]]:
    """The channels advertised, and the first ``want`` messages of ``topic`` once subscribed."""
    # foxglove-sdk answers no close frame: do not wait the default 10 s for one
    async with websockets.connect("ws://127.0.0.1:%d" % port, subprotocols=[SUBPROTOCOL], close_timeout=0.5) as ws:
        channels = {}
        while topic not in channels:
            frame = json.loads(await asyncio.wait_for(ws.recv(), 10))
            if frame["op"] == "advertise":
                channels.update({c["topic"]: c for c in frame["channels"]})
        await ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 1, "channelId": channels[topic]["id"]}]}))
        await asyncio.sleep(0.3)  # the subscription reaches the server before the machine runs
        started.set()
        got = []
        while len(got) < want or "/fsmscope/log" not in channels:
            frame = await asyncio.wait_for(ws.recv(), 10)
            if isinstance(frame, bytes) and frame[0] == 1:  # MessageData: op, subscription, log time, payload
                got.append(json.loads(frame[1 + 4 + 8:]))
            elif isinstance(frame, str) and json.loads(frame)["op"] == "advertise":  # channels of later events
                channels.update({c["topic"]: c for c in json.loads(frame)["channels"]})
        return channels, got


@contextlib.contextmanager
def looping_with_foxglove():
    """A server serving 'loop' (a two-state loop of 20 rounds, not started) and a Foxglove server fed
    from its hub: (the machine, the Foxglove server)."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    srv = ServerThread().start()
    try:
        sm = two_state_loop(20)
        srv.hub.add_local(sm, name="loop")
        live = start_foxglove(foxglove_args(), srv.hub)
        try:
            yield sm, live
        finally:
            live.stop()
    finally:
        srv.stop()


def test_a_foxglove_client_sees_the_channels_and_the_active_state_change():
    with looping_with_foxglove() as (sm, live):
        started = threading.Event()
        runner = threading.Thread(target=lambda: started.wait(10) and sm.execute(), daemon=True)
        runner.start()
        with concurrent.futures.ThreadPoolExecutor(1) as own_loop:  # the suite's thread may run a loop
            channels, states = own_loop.submit(asyncio.run, watch(live.port, "/fsmscope/loop/state", started,
                                                                  10)).result()
        runner.join(10)
    assert channels["/fsmscope/loop/state"]["schemaName"] == "fsmscope.State"
    assert channels["/fsmscope/loop/events"]["schemaName"] == "fsmscope.Event"
    assert (channels["/fsmscope/log"]["schemaName"], channels["/fsmscope/log"]["encoding"]) == ("foxglove.Log", "protobuf")
    assert {s["active"] for s in states} >= {"/SM_ROOT/A", "/SM_ROOT/B"}


def own_address() -> str:
    """This computer's address on its network (no packet is sent)."""
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.connect(("10.255.255.255", 1))
        return s.getsockname()[0]


def test_the_foxglove_server_listens_on_the_loopback_only_whatever_host_says():
    address = own_address()
    if address.startswith("127."):
        pytest.skip("this computer has no address but the loopback")
    srv = ServerThread().start()
    try:
        live = start_foxglove(foxglove_args(host="0.0.0.0"), srv.hub)
        try:
            with pytest.raises(ConnectionRefusedError):
                socket.create_connection((address, live.port), timeout=5).close()
            socket.create_connection(("127.0.0.1", live.port), timeout=5).close()
        finally:
            live.stop()
    finally:
        srv.stop()


async def first_messages(port: int, topic: str, want: int) -> list[dict]:
    """The first ``want`` messages of ``topic`` once a client has subscribed to it."""
    async with websockets.connect("ws://127.0.0.1:%d" % port, subprotocols=[SUBPROTOCOL], close_timeout=0.5) as ws:
        channels = {}
        while topic not in channels:
            frame = await asyncio.wait_for(ws.recv(), 20)
            if isinstance(frame, str) and json.loads(frame)["op"] == "advertise":
                channels.update({c["topic"]: c for c in json.loads(frame)["channels"]})
        await ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 1, "channelId": channels[topic]["id"]}]}))
        got = []
        while len(got) < want:
            frame = await asyncio.wait_for(ws.recv(), 20)
            if isinstance(frame, bytes) and frame[0] == 1:
                got.append(json.loads(frame[1 + 4 + 8:]))
        return got


def foxglove_port_of(command: list[str], timeout: float = 30.0) -> tuple[subprocess.Popen, int]:
    """``fsmscope COMMAND`` in a real process, and the port of the Foxglove server it says it serves
    (AssertionError with what it said when it says none within ``timeout`` seconds). The process's
    ``said``: the lines of its stderr up to that one; ``more``: a queue of the next ones."""
    proc = subprocess.Popen([sys.executable, "-m", "fsmscope", *command], cwd=ROOT, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            env=dict(os.environ, PYTHONPATH=ROOT))
    lines: queue.Queue = queue.Queue()
    threading.Thread(target=lambda: [lines.put(line) for line in proc.stderr] and None, daemon=True).start()
    said = []
    try:
        while True:
            said.append(lines.get(timeout=timeout))
            found = re.search(r"Foxglove WebSocket at ws://127\.0\.0\.1:(\d+)", said[-1])
            if found:
                proc.said, proc.more = said, lines
                return proc, int(found.group(1))
    except queue.Empty:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(10)
        raise AssertionError("fsmscope %s said no Foxglove server: %r" % (command[0], said)) from None


LOOPING = """
import time
import fsm
sm = fsm.StateMachine(["done"])
ticks = [0]
def tick(ud):
    time.sleep(0.02)
    ticks[0] += 1
    return "stop" if ticks[0] >= 1500 else "go"
with sm:
    fsm.StateMachine.add("A", fsm.CBState(tick, outcomes=["go", "stop"]), {"go": "B", "stop": "done"})
    fsm.StateMachine.add("B", fsm.CBState(tick, outcomes=["go", "stop"]), {"go": "A", "stop": "done"})
sm.execute()
"""


def states_seen(command: list[str], topic: str) -> set[str]:
    """The active states ``topic`` says to a Foxglove client of ``fsmscope COMMAND``."""
    proc, port = foxglove_port_of(command)
    try:
        with concurrent.futures.ThreadPoolExecutor(1) as own_loop:
            states = own_loop.submit(asyncio.run, first_messages(port, topic, 10)).result()
    finally:
        os.killpg(proc.pid, signal.SIGTERM)
        proc.wait(20)
    return {s["active"] for s in states} - {""}  # "": idle, between two runs of the looping demo


def test_a_script_run_without_a_dashboard_serves_foxglove_its_active_states(tmp_path):
    script = tmp_path / "looping.py"
    script.write_text(LOOPING)
    seen = states_seen(["run", str(script), "--no-serve", "--foxglove", "0", "--record", str(tmp_path / "r.jsonl")],
                       "/fsmscope/looping/state")
    assert seen >= {"/SM_ROOT/A", "/SM_ROOT/B"}


def test_the_headless_demo_serves_foxglove_its_active_states(tmp_path):
    seen = states_seen(["demo", "--headless", "--fast", "--foxglove", "0", "--record", str(tmp_path / "d.jsonl")],
                       "/fsmscope/pick_place/state")
    assert len(seen) >= 2 and all(s.startswith("/SM_ROOT") for s in seen)


def test_a_client_offering_only_the_older_foxglove_websocket_v1_is_refused():
    """docs/interop.md: foxglove-sdk speaks foxglove.sdk.v1 only (what @foxglove/ws-protocol 0.8.0 offers is refused)."""
    from fsmscope.interop.foxglove_live import FoxgloveLive

    live = FoxgloveLive(port=0)

    async def offer(subprotocol: str) -> None:
        async with websockets.connect("ws://127.0.0.1:%d" % live.port, subprotocols=[subprotocol], close_timeout=0.5):
            pass
    try:
        with concurrent.futures.ThreadPoolExecutor(1) as own_loop:
            own_loop.submit(asyncio.run, offer(SUBPROTOCOL)).result()
            with pytest.raises(websockets.InvalidStatus) as refused:
                own_loop.submit(asyncio.run, offer("foxglove.websocket.v1")).result()
    finally:
        live.stop()
    assert refused.value.response.status_code == 400


def handshake(port: int, host: str, origin: str | None = None) -> str:
    """The status line that the Foxglove server answers a raw websocket handshake with."""
    head = ("GET / HTTP/1.1\r\nHost: %s\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
            "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
            "Sec-WebSocket-Protocol: %s\r\n" % (host, SUBPROTOCOL))
    if origin is not None:
        head += "Origin: %s\r\n" % origin
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall((head + "\r\n").encode())
        return s.makefile("rb").readline().decode().strip()


def test_a_handshake_naming_another_host_is_refused_and_the_loopback_s_names_are_answered():
    from fsmscope.interop.foxglove_live import FoxgloveLive

    live = FoxgloveLive(port=0)
    try:
        assert handshake(live.port, "evil.example:%d" % live.port).startswith("HTTP/1.1 403")
        for name in ("127.0.0.1:%d" % live.port, "localhost:%d" % live.port, "[::1]:%d" % live.port, "localhost:9"):
            assert handshake(live.port, name).startswith("HTTP/1.1 101"), name
    finally:
        live.stop()


def test_refused_handshakes_are_said_once_and_the_start_up_line_says_who_may_connect(tmp_path):
    script = tmp_path / "looping.py"
    script.write_text(LOOPING)
    proc, port = foxglove_port_of(["run", str(script), "--no-serve", "--foxglove", "0", "--foxglove-origin",
                                   "http://tools.internal:8080", "--record", str(tmp_path / "r.jsonl")])
    try:
        for i in range(200):
            assert handshake(port, "127.0.0.1", origin="https://evil.example").startswith("HTTP/1.1 403")
            assert handshake(port, "evil.example").startswith("HTTP/1.1 403")
        assert handshake(port, "127.0.0.1", origin="http://tools.internal:8080").startswith("HTTP/1.1 101")
    finally:
        os.killpg(proc.pid, signal.SIGTERM)
        proc.wait(20)
    time.sleep(0.2)  # the reader of its stderr takes the last lines
    said = list(proc.more.queue)
    assert sum("Foxglove connection was refused" in line for line in said) == 1, said
    assert len(said) < 5, said
    assert "https://app.foxglove.dev, http://tools.internal:8080 may connect" in proc.said[-1]


def test_nothing_is_converted_for_foxglove_while_no_client_is_connected():
    with looping_with_foxglove() as (sm, live):
        fed = []
        live.event = fed.append
        sm.execute()
        time.sleep(0.3)  # the pump looks every 50 ms
    assert fed == []
