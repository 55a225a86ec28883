"""Machines of the original smach to control from a real server, and what the server says of them:
shared by tests/server/test_original_control.py and test_original_debug.py. The fixture ``smach`` is
the original of each branch in turn (noetic-devel, ros2); ``loop`` serves a looping machine of it."""

import contextlib
import threading
import time

import fsm
import pytest
from fsmscope import Publisher
from fsmscope.server.testing.polling import wait_for

from original_core import loaded_original
from server_support import client, looping_machine


class Bare:
    """SMACH runs any object with a state's interface: this one has no preempt methods and takes no
    attribute (``__slots__``); it returns 'go'."""

    __slots__ = ()

    def get_registered_outcomes(self):
        return ("go",)

    def get_registered_input_keys(self):
        return ()

    def get_registered_output_keys(self):
        return ()

    def execute(self, ud):
        return "go"


@pytest.fixture(scope="module", params=["noetic", "ros2"])
def smach(request):
    """The original of each branch in turn, its log lines kept out of the test's output (they print otherwise)."""
    with loaded_original(request.param) as module:
        module.set_loggers(*[lambda msg: None] * 4)
        yield module


def visiting(smach):
    """FOO -go-> BAR -go-> done of the original; each appends its label to userdata ``visits``."""
    sm = smach.StateMachine(outcomes=["done"])
    sm.userdata.visits = []

    def visit(label):
        def cb(ud):
            ud.visits = ud.visits + [label]
            return "go"
        return smach.CBState(cb, outcomes=["go"], input_keys=["visits"], output_keys=["visits"])

    with sm:
        smach.StateMachine.add("FOO", visit("FOO"), {"go": "BAR"})
        smach.StateMachine.add("BAR", visit("BAR"), {"go": "done"})
    return sm


def waiter(smach):
    """A state of the original that waits until preempted (then 'preempted') or released (then 'done')."""
    entered, release = threading.Event(), threading.Event()

    class Wait(smach.State):
        def __init__(self):
            smach.State.__init__(self, outcomes=["done", "preempted"])

        def execute(self, ud):
            entered.set()
            while not release.is_set():
                if self.preempt_requested():
                    self.service_preempt()
                    return "preempted"
                time.sleep(0.005)
            return "done"

    return Wait(), entered, release


def waiting(smach):
    """WAIT (``waiter``) alone in a StateMachine of the original."""
    wait, entered, release = waiter(smach)
    sm = smach.StateMachine(outcomes=["done", "preempted"])
    with sm:
        smach.StateMachine.add("WAIT", wait, {"done": "done", "preempted": "preempted"})
    return sm, entered, release


def run_in_thread(sm):
    result = {}
    thread = threading.Thread(target=lambda: result.update(outcome=sm.execute()), daemon=True)
    thread.start()
    return thread, result


def status(http, name):
    return http.get("/api/machines/%s/status" % name).json()


def holds(http, name="loop"):
    debug = status(http, name)["debug"]  # None until a debugger is attached
    return debug["holds"] if debug is not None else []


@pytest.fixture
def loop(live_server, smach):
    """The looping original machine served as 'loop', running in a thread; stopped and resumed at the end."""
    sm, stop = looping_machine(smach)
    live_server.hub.add_local(sm, name="loop")
    http = client(live_server)
    thread, result = run_in_thread(sm)
    yield http, stop, result
    stop.set()
    http.put("/api/machines/loop/breakpoints", json={"breakpoints": []})
    http.post("/api/machines/loop/resume")
    thread.join(5)


def split_machine(smach, left):
    """SPLIT, an original Concurrence of ``left`` and RIGHT (returns 'done' at once), in a StateMachine;
    'done' when both are done."""
    sm = smach.StateMachine(outcomes=["done", "other", "preempted"])
    with sm:
        split = smach.Concurrence(outcomes=["done", "other", "preempted"], default_outcome="other",
                                  outcome_map={"done": {"LEFT": "done", "RIGHT": "done"}})
        with split:
            smach.Concurrence.add("LEFT", left)
            smach.Concurrence.add("RIGHT", smach.CBState(lambda ud: "done", outcomes=["done"]))
        smach.StateMachine.add("SPLIT", split, {"done": "done", "other": "other", "preempted": "preempted"})
    return sm


@contextlib.contextmanager
def published(live_server, sm):
    """``sm`` published to the server by a Publisher (in this process, over a real websocket): the
    controls reach it as control frames, applied by the same handle; yields its run's thread and result."""
    publisher = Publisher(live_server.base_url, live_server.token)
    try:
        fsm.attach(sm, publisher, name="remote")
        assert publisher.connected.wait(5)
        thread, result = run_in_thread(sm)
        wait_for(lambda: any(m["name"] == "remote" and m["running"]
                             for m in client(live_server).get("/api/machines").json()))
        yield thread, result
    finally:
        publisher.close()
