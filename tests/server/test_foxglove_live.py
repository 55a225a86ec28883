"""`--foxglove PORT`: a Foxglove client (a real websocket, Foxglove's subprotocol) connected to the
foxglove-sdk server that the hub feeds sees the machine's channels and its active state change."""

from __future__ import annotations

import argparse
import asyncio
import concurrent.futures
import json
import socket
import threading

import fsm
import pytest
import websockets
from recording_support import two_state_loop

from server.cli.foxglove_bridge import start_foxglove
from server.http_server import ServerThread

SUBPROTOCOL = "foxglove.sdk.v1"


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


def test_a_foxglove_client_sees_the_channels_and_the_active_state_change():
    fsm.set_loggers(*(lambda msg: None,) * 4)
    srv = ServerThread().start()
    try:
        sm = two_state_loop(20)
        srv.hub.add_local(sm, name="loop")
        live = start_foxglove(argparse.Namespace(host="127.0.0.1", foxglove=0), srv.hub)
        started = threading.Event()
        runner = threading.Thread(target=lambda: started.wait(10) and sm.execute(), daemon=True)
        runner.start()
        try:
            with concurrent.futures.ThreadPoolExecutor(1) as own_loop:  # the suite's thread may run a loop
                channels, states = own_loop.submit(asyncio.run, watch(live.port, "/fsmscope/loop/state", started,
                                                                      10)).result()
        finally:
            live.stop()
        runner.join(10)
    finally:
        srv.stop()
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
        live = start_foxglove(argparse.Namespace(host="0.0.0.0", foxglove=0), srv.hub)
        try:
            with pytest.raises(ConnectionRefusedError):
                socket.create_connection((address, live.port), timeout=5).close()
            socket.create_connection(("127.0.0.1", live.port), timeout=5).close()
        finally:
            live.stop()
    finally:
        srv.stop()
