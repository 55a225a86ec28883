"""Helpers for the server tests: small machines, an authenticated HTTP client, websocket frames."""

import contextlib
import json
import threading
import time

import fsm
import httpx
from fsmscope.server.testing.polling import wait_for
from websockets.sync.client import connect


def sleeper(seconds=0.0, outcome="go"):
    def cb(ud):
        time.sleep(seconds)
        return outcome
    return fsm.CBState(cb, outcomes=[outcome])


def two_state_machine(delay=0.0):
    """FOO -go-> BAR -go-> done; each state sleeps ``delay`` and counts its visits in userdata."""
    sm = fsm.StateMachine(outcomes=["done"])
    sm.userdata.visits = []

    def visit(label):
        def cb(ud):
            time.sleep(delay)
            ud.visits = ud.visits + [label]
            return "go"
        return fsm.CBState(cb, outcomes=["go"], input_keys=["visits"], output_keys=["visits"])

    with sm:
        fsm.StateMachine.add("FOO", visit("FOO"), {"go": "BAR"})
        fsm.StateMachine.add("BAR", visit("BAR"), {"go": "done"})
    return sm


class Waiting(fsm.State):
    """Waits until preempted (then 'preempted') or until ``release`` is set (then 'done')."""

    def __init__(self):
        fsm.State.__init__(self, outcomes=["done", "preempted"])
        self.entered = threading.Event()
        self.release = threading.Event()

    def execute(self, ud):
        self.entered.set()
        while not self.release.is_set():
            if self.preempt_requested():
                self.service_preempt()
                return "preempted"
            time.sleep(0.005)
        return "done"


class Stubborn(fsm.State):
    """Never services a preempt: runs until ``release`` is set (a preempt stays pending meanwhile)."""

    def __init__(self):
        fsm.State.__init__(self, outcomes=["done"])
        self.entered = threading.Event()
        self.release = threading.Event()

    def execute(self, ud):
        self.entered.set()
        self.release.wait(60)
        return "done"


def waiting_machine():
    sm = fsm.StateMachine(outcomes=["done", "preempted"])
    wait = Waiting()
    with sm:
        fsm.StateMachine.add("WAIT", wait, {"done": "done", "preempted": "preempted"})
    return sm, wait


def nested_machine():
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        sub = fsm.StateMachine(outcomes=["done"])
        with sub:
            fsm.StateMachine.add("A", sleeper(), {"go": "B"})
            fsm.StateMachine.add("B", sleeper(), {"go": "done"})
        fsm.StateMachine.add("SUB", sub, {"done": "C"})
        fsm.StateMachine.add("C", sleeper(), {"go": "done"})
    return sm


def client(srv, token=True):
    headers = {"Authorization": "Bearer " + srv.token} if token else {}
    return httpx.Client(base_url=srv.base_url, headers=headers, timeout=10)


def control_events(http, name, action=None):
    """The machine's ``control`` events (of ``action``), read as a client that keeps the server's
    read budget would: a read answered 429 is asked again after the Retry-After it says (a test
    polling a busy machine's history spends its 2 % of a core quickly on a loaded computer)."""
    while True:
        answer = http.get("/api/machines/%s/history" % name, params={"kinds": "control", "limit": 1000})
        if answer.status_code != 429:
            break
        time.sleep(float(answer.headers["Retry-After"]))
    answer.raise_for_status()
    return [e for e in answer.json()["events"] if action is None or e["action"] == action]


def stream(srv, name, since=None, token=True, **kw):
    url = "ws://127.0.0.1:%d/api/machines/%s/stream" % (srv.port, name)
    params = []
    if token:
        params.append("token=" + srv.token)
    if since is not None:
        params.append("since=%d" % since)
    if params:
        url += "?" + "&".join(params)
    return connect(url, compression=None, open_timeout=5, **kw)


def frames(ws, until, timeout=5.0):
    """Receive frames until ``until(frames)`` is true; returns the parsed frames."""
    got = []

    def receive_one() -> bool:
        with contextlib.suppress(TimeoutError):
            got.append(json.loads(ws.recv(timeout=0.05)))
        return until(got)

    wait_for(lambda: until(got) or receive_one(), timeout, interval=0,
             what=lambda: "the frames wanted; frames so far: %r" % got[-5:])
    return got


def events_of(frame_list):
    return [e for f in frame_list if f["type"] == "events" for e in f["events"]]


def blob_loop(n, size=2000):
    """A one-state loop that runs ``n`` times, writing ``size`` bytes of userdata each time (big frames)."""
    count = {"n": 0}

    def step(ud):
        count["n"] += 1
        ud.blob = "x" * size
        if count["n"] >= n:
            count["n"] = 0
            return "stop"
        return "again"

    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(step, outcomes=["again", "stop"], output_keys=["blob"]),
                             {"again": "A", "stop": "done"})
    return sm


def looping_machine(smach=fsm):
    """A <-> B until ``stop`` is set; each writes its count into userdata ``n``. ``smach``: fsm, or
    the original SMACH (tests/original_control_support.py)."""
    stop = threading.Event()
    count = {"n": 0}

    def tick(ud):
        time.sleep(0.002)
        count["n"] += 1
        ud.n = count["n"]
        return "stop" if stop.is_set() else "go"

    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("A", smach.CBState(tick, outcomes=["go", "stop"], output_keys=["n"]),
                               {"go": "B", "stop": "done"})
        smach.StateMachine.add("B", smach.CBState(tick, outcomes=["go", "stop"], output_keys=["n"]),
                               {"go": "A", "stop": "done"})
    return sm, stop
