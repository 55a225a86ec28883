"""``fsmscope.IntrospectionServer(name, sm, "/SM_ROOT")`` given a machine of the original SMACH (each
branch's core), as smach_ros's is given one: the real server (uvicorn, in this process) serves its
structure and its live status, and a machine whose user code hangs, raises or holds userdata that
cannot be encoded is shown (opaque values with their type names) without taking the machine or the
server down."""

import socket
import threading

import httpx
import numpy
import pytest
from fsmscope import IntrospectionServer
from fsmscope.server.testing.polling import wait_for

pytestmark = pytest.mark.timeout(30)


def http(sis):
    return httpx.Client(base_url="http://127.0.0.1:%d" % sis.port, timeout=5,
                        headers={"Authorization": "Bearer " + sis.token})


def blocked_machine(smach, userdata=None):
    """ROOT > SUB > (WRITE, which stores ``userdata``'s values, then BLOCK, which waits until released)."""

    class Write(smach.State):
        def __init__(self):
            smach.State.__init__(self, outcomes=["done"], output_keys=list(userdata or {}))

        def execute(self, ud):
            for key, value in (userdata or {}).items():
                ud[key] = value
            return "done"

    class Block(smach.State):
        def __init__(self):
            smach.State.__init__(self, outcomes=["done"])
            self.entered, self.release = threading.Event(), threading.Event()

        def execute(self, ud):
            self.entered.set()
            self.release.wait(20)
            return "done"

    block = Block()
    sub = smach.StateMachine(outcomes=["done"], output_keys=list(userdata or {}))
    with sub:
        smach.StateMachine.add("WRITE", Write(), transitions={"done": "BLOCK"})
        smach.StateMachine.add("BLOCK", block)
    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("SUB", sub)
    return sm, block


@pytest.fixture
def quiet(core):
    """The core's lines not printed (they would flood the test's output)."""
    core.set_loggers(*[lambda msg: None] * 4)
    return core


def served(sis, sm):
    """Run ``sm`` in a thread while ``sis`` serves it; returns the thread and a box for the outcome."""
    box = []
    thread = threading.Thread(target=lambda: box.append(sm.execute()), daemon=True)
    thread.start()
    return thread, box


def test_the_introspection_server_serves_an_original_machines_structure_and_live_status(quiet):
    sm, block = blocked_machine(quiet)
    sis = IntrospectionServer("orig", sm, "/SM_ROOT").start()
    try:
        thread, box = served(sis, sm)
        assert block.entered.wait(5)
        with http(sis) as client:
            root = client.get("/api/machines/orig/structure").json()
            assert [c["label"] for c in root["children"]] == ["SUB"]
            assert [c["label"] for c in root["children"][0]["children"]] == ["WRITE", "BLOCK"]
            status = wait_for(lambda: (s := client.get("/api/machines/orig/status").json())["containers"]
                              .get("/SM_ROOT/SUB", {}).get("active") == ["BLOCK"] and s)
            assert status["running"] and status["containers"]["/SM_ROOT"]["active"] == ["SUB"]
            block.release.set()
            thread.join(5)
            assert box == ["done"]
            status = wait_for(lambda: (s := client.get("/api/machines/orig/status").json())["outcome"] and s)
            assert (status["running"], status["outcome"]) == (False, "done")
    finally:
        block.release.set()
        sis.stop()


def test_a_state_hanging_in_execute_leaves_the_server_answering(quiet):
    sm, block = blocked_machine(quiet)
    sis = IntrospectionServer("hung", sm, "/SM_ROOT").start()
    try:
        served(sis, sm)
        assert block.entered.wait(5)
        with http(sis) as client:
            for _ in range(3):
                assert client.get("/api/machines").status_code == 200
                assert client.get("/api/machines/hung/status").json()["running"] is True
    finally:
        block.release.set()
        sis.stop()


class Unprintable:
    """A value whose repr raises."""

    def __repr__(self):
        raise ValueError("no repr")


class Point:
    """Shaped as a ROS message is (genpy's): slots and a type, no dict."""

    __slots__ = ("x", "y")
    _type = "geometry_msgs/Point"

    def __init__(self):
        self.x, self.y = 1.0, 2.0


def test_userdata_that_cannot_be_encoded_shows_as_opaque_values_and_nothing_goes_down(quiet):
    lock, sock = threading.Lock(), socket.socket()
    try:
        values = {"lock": lock, "sock": sock, "array": numpy.arange(3), "unprintable": Unprintable(),
                  "point": Point()}
        sm, block = blocked_machine(quiet, values)
        sis = IntrospectionServer("bad", sm, "/SM_ROOT").start()
        try:
            thread, box = served(sis, sm)
            assert block.entered.wait(5)
            with http(sis) as client:
                def shown():
                    sub = client.get("/api/machines/bad/status").json()["containers"].get("/SM_ROOT/SUB", {})
                    return "point" in sub.get("userdata", {}) and sub["userdata"]
                userdata = wait_for(shown, what="SUB's userdata")
            assert "_thread.lock" in userdata["lock"]["$repr"]
            assert userdata["sock"]["$repr"].startswith("<socket.socket")
            assert userdata["array"] == [0, 1, 2]  # numpy's arrays as lists (docs/events.md)
            assert userdata["unprintable"] == {"$repr": "<unrepresentable Unprintable: ValueError>"}
            assert "Point" in userdata["point"]["$repr"]
            block.release.set()
            thread.join(5)
            assert box == ["done"]  # the machine ran to its end, its userdata what it was given
            assert sm.userdata["lock"] is lock and sm.userdata["sock"] is sock
        finally:
            block.release.set()
            sis.stop()
    finally:
        sock.close()


def test_a_state_that_raises_is_shown_as_the_error_and_the_server_stays_up(quiet):
    class Bad(quiet.State):
        def __init__(self):
            quiet.State.__init__(self, outcomes=["done"])

        def execute(self, ud):
            raise KeyError("gripper")

    sm = quiet.StateMachine(outcomes=["done"])
    with sm:
        quiet.StateMachine.add("BAD", Bad())
    sis = IntrospectionServer("raises", sm, "/SM_ROOT").start()
    try:
        with pytest.raises(quiet.InvalidUserCodeError):
            sm.execute()
        with http(sis) as client:
            status = wait_for(lambda: (s := client.get("/api/machines/raises/status").json())["error"] and s)
            assert (status["error"]["state"], status["error"]["exc_type"], status["error"]["message"]) == (
                "BAD", "KeyError", "'gripper'")
            assert (status["running"], status["outcome"]) == (False, None)
            assert client.get("/api/machines").status_code == 200
    finally:
        sis.stop()
