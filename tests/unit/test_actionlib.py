"""fsm.ros.actionlib: a SimpleActionServer and SimpleActionClient talking over a bus, with real threads."""

import threading

import pytest

from fsm.ros.actionlib import GoalStatus, SimpleActionClient, SimpleActionServer
from bus_support import serve, until_preempted
from fsmscope.server.testing.polling import wait_for


def running_goal(bus, servers):
    """A server whose goal runs until preempted, and a client whose goal it is running."""
    started = threading.Event()
    server = serve(bus, servers, lambda goal: (started.set(), until_preempted(server)(goal)))
    client = SimpleActionClient("act", bus=bus)
    client.send_goal("g")
    assert started.wait(1.0)
    return server, client


def test_goal_status_names():
    assert [GoalStatus.name(s) for s in range(5)] == ["PENDING", "ACTIVE", "PREEMPTED", "SUCCEEDED", "ABORTED"]
    assert GoalStatus.name(9) == "UNKNOWN (9)"


def test_goal_succeeds_with_its_result_and_text(bus, servers):
    server = serve(bus, servers, lambda goal: server.set_succeeded({"double": goal * 2}, "done"))
    client = SimpleActionClient("act", bus=bus)
    assert client.wait_for_server(timeout=1.0)
    client.send_goal(21)
    assert client.wait_for_result(timeout=1.0)
    assert client.get_state() == GoalStatus.SUCCEEDED
    assert client.get_result() == {"double": 42}
    assert client.get_goal_status_text() == "done"


def test_execute_cb_runs_in_the_server_worker_thread(bus, servers):
    threads = []
    server = serve(bus, servers, lambda goal: (threads.append(threading.current_thread()), server.set_succeeded()))
    client = SimpleActionClient("act", bus=bus)
    client.send_goal(None)
    client.wait_for_result(timeout=1.0)
    assert threads and threads[0] is not threading.current_thread()


def test_callbacks_get_active_feedback_and_done(bus, servers):
    def execute(goal):
        server.publish_feedback(1)
        server.publish_feedback(2)
        server.set_aborted("res", "failed")
    server = serve(bus, servers, execute)
    seen = []
    done = threading.Event()
    client = SimpleActionClient("act", bus=bus)
    client.send_goal("g", done_cb=lambda status, result: (seen.append(("done", status, result)), done.set()),
                     active_cb=lambda: seen.append("active"), feedback_cb=lambda fb: seen.append(("fb", fb)))
    assert done.wait(1.0)
    assert seen == ["active", ("fb", 1), ("fb", 2), ("done", GoalStatus.ABORTED, "res")]


def test_cancel_goal_requests_preempt_of_the_active_goal(bus, servers):
    server, client = running_goal(bus, servers)
    assert server.is_active() and not server.is_preempt_requested()
    client.cancel_goal()
    assert client.wait_for_result(timeout=1.0)
    assert client.get_state() == GoalStatus.PREEMPTED
    assert client.get_result() == {"stopped": "g"}


def test_new_goal_preempts_the_active_one(bus, servers):
    server, first = running_goal(bus, servers)
    second = SimpleActionClient("act", bus=bus)
    second.send_goal("two")
    assert first.wait_for_result(timeout=1.0)
    assert first.get_state() == GoalStatus.PREEMPTED
    assert second.get_state() in (GoalStatus.PENDING, GoalStatus.ACTIVE)
    second.cancel_goal()
    assert second.wait_for_result(timeout=1.0)


def test_pending_goal_replaced_by_a_newer_one_is_preempted_without_running(bus, servers):
    release = threading.Event()
    ran = []

    def execute(goal):
        ran.append(goal)
        release.wait(1.0)
        server.set_succeeded()
    server = serve(bus, servers, execute)
    clients = [SimpleActionClient("act", bus=bus) for _ in range(3)]
    clients[0].send_goal("a")
    wait_for(server.is_active)
    clients[1].send_goal("b")
    clients[2].send_goal("c")
    assert clients[1].wait_for_result(timeout=1.0)
    assert clients[1].get_state() == GoalStatus.PREEMPTED
    assert "another goal was received" in clients[1].get_goal_status_text()
    release.set()
    assert clients[2].wait_for_result(timeout=1.0)
    assert ran == ["a", "c"]


def test_execute_cb_returning_without_a_status_aborts_with_a_warning(bus, servers, logs):
    serve(bus, servers, lambda goal: None)
    client = SimpleActionClient("act", bus=bus)
    client.send_goal("g")
    assert client.wait_for_result(timeout=1.0)
    assert client.get_state() == GoalStatus.ABORTED
    assert "did not set the goal to a terminal status" in logs.warn[0]


def test_execute_cb_exception_aborts_with_the_traceback_as_text(bus, servers, logs):
    def execute(goal):
        raise RuntimeError("arm jammed")
    serve(bus, servers, execute)
    client = SimpleActionClient("act", bus=bus)
    client.send_goal("g")
    assert client.wait_for_result(timeout=1.0)
    assert client.get_state() == GoalStatus.ABORTED
    text = client.get_goal_status_text()
    assert text.startswith("Traceback") and "RuntimeError: arm jammed" in text
    assert "Exception in your execute callback" in logs.error[0]


def test_raising_client_callback_is_logged_and_the_goal_still_ends(bus, servers, logs):
    server = serve(bus, servers, lambda goal: server.set_succeeded())
    client = SimpleActionClient("act", bus=bus)
    client.send_goal("g", done_cb=lambda status, result: 1 / 0)
    assert client.wait_for_result(timeout=1.0)
    assert client.get_state() == GoalStatus.SUCCEEDED
    assert any("action done callback" in line for line in logs.error)


def test_goal_sent_with_no_server_is_aborted_at_once(bus, logs):
    client = SimpleActionClient("nobody", bus=bus)
    assert not client.wait_for_server(timeout=0.01)
    client.send_goal("g")
    assert client.wait_for_result(timeout=0)
    assert client.get_state() == GoalStatus.ABORTED
    assert "not running" in client.get_goal_status_text()


def test_wait_for_result_times_out_while_the_goal_runs(bus, servers):
    server, client = running_goal(bus, servers)
    assert not client.wait_for_result(timeout=0.05)
    client.cancel_goal()
    assert client.wait_for_result(timeout=1.0)


def test_client_without_goal_reports_errors_not_exceptions(bus, logs):
    client = SimpleActionClient("act", bus=bus)
    assert not client.wait_for_result(timeout=0)
    assert client.get_state() == GoalStatus.PENDING
    assert client.get_result() is None
    assert client.get_goal_status_text() == ""
    assert len(logs.error) == 3


def test_auto_start_false_registers_only_on_start(bus, servers):
    server = serve(bus, servers, lambda goal: server.set_succeeded(), auto_start=False)
    client = SimpleActionClient("act", bus=bus)
    assert not client.wait_for_server(timeout=0.01)
    server.start()
    assert client.wait_for_server(timeout=1.0)


def test_shutdown_preempts_the_active_goal_and_unregisters(bus, servers):
    server, client = running_goal(bus, servers)
    assert server.shutdown(timeout=1.0)
    assert client.get_state() == GoalStatus.PREEMPTED
    assert bus.action_server("act") is None


def test_set_status_without_an_active_goal_is_an_error(bus, servers, logs):
    server = serve(bus, servers, lambda goal: None)
    server.set_succeeded()
    assert "must be active" in logs.error[0]


def test_two_servers_cannot_share_a_name(bus, servers):
    serve(bus, servers, lambda goal: None)
    with pytest.raises(ValueError):
        SimpleActionServer("act", lambda goal: None, bus=bus)
