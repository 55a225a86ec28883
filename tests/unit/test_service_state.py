"""ServiceState (API.md §14): request building, the call, the response, failures and preemption."""

import threading
import time
from types import SimpleNamespace

import fsm as smach
import pytest

from fsmscope.server.testing.polling import wait_for
from fsm.ros.bus import default_bus
from fsm.ros.service_state import ServiceState
from smach_support import Background, machine, userdata


def add_service(bus, name="add"):
    """A service whose response is an object with a ``sum`` attribute; records its requests."""
    requests = []

    def handler(req):
        requests.append(req)
        return SimpleNamespace(sum=req["a"] + req["b"])
    bus.advertise_service(name, handler)
    return requests


def test_outcomes_always_include_succeeded_aborted_preempted(bus):
    @smach.cb_interface(outcomes=["odd"])
    def response_cb(ud, response):
        return None
    state = ServiceState("add", response_cb=response_cb, outcomes=["extra"], bus=bus)
    assert set(state.get_registered_outcomes()) == {"succeeded", "aborted", "preempted", "extra", "odd"}


def test_keys_and_slots_are_registered_as_input_and_output_keys(bus):
    state = ServiceState("add", request_key="req", request_slots=["a"], response_key="resp",
                         response_slots=["sum"], input_keys=["i"], output_keys=["o"], bus=bus)
    assert set(state.get_registered_input_keys()) == {"req", "a", "i"}
    assert set(state.get_registered_output_keys()) == {"resp", "sum", "o"}


def test_calls_with_the_given_request_and_stores_the_response(bus):
    add_service(bus)
    ud = userdata()
    state = ServiceState("add", request={"a": 1, "b": 2}, response_key="resp", bus=bus)
    assert state.execute(ud) == "succeeded"
    assert ud.resp.sum == 3


def test_default_request_is_built_from_the_spec_or_is_an_empty_dict(bus):
    requests = []
    bus.advertise_service("echo", lambda req: requests.append(req))

    class Request:
        pass
    assert ServiceState("echo", Request, bus=bus).execute(userdata()) == "succeeded"
    assert ServiceState("echo", bus=bus).execute(userdata()) == "succeeded"
    assert isinstance(requests[0], Request) and requests[1] == {}


def test_request_is_taken_from_the_request_key(bus):
    requests = add_service(bus)
    state = ServiceState("add", request_key="req", bus=bus)
    assert state.execute(userdata(req={"a": 5, "b": 6})) == "succeeded"
    assert requests == [{"a": 5, "b": 6}]


def test_missing_request_key_aborts_with_an_error(bus, logs):
    add_service(bus)
    state = ServiceState("add", request_key="req", bus=bus)
    assert state.execute(userdata()) == "aborted"
    assert "Requested request key 'req' not in userdata struture" in logs.error[0]


def test_request_slots_fill_dict_items_and_object_attributes(bus):
    requests = []
    bus.advertise_service("echo", lambda req: requests.append(req))

    class Request:
        a = b = None
    ud = userdata(a=1, b=2)
    assert ServiceState("echo", request_slots=["a", "b"], bus=bus).execute(ud) == "succeeded"
    assert ServiceState("echo", Request, request_slots=["a", "b"], bus=bus).execute(ud) == "succeeded"
    assert requests[0] == {"a": 1, "b": 2}
    assert (requests[1].a, requests[1].b) == (1, 2)


def test_missing_request_slot_aborts_with_an_error(bus, logs):
    add_service(bus)
    state = ServiceState("add", request_slots=["a", "b"], bus=bus)
    assert state.execute(userdata(a=1)) == "aborted"
    assert "Requested request slot key 'b' is not in userdata strcture" in logs.error[0]


def test_request_cb_return_replaces_the_request_and_none_keeps_it(bus):
    requests = add_service(bus)
    ServiceState("add", request_cb=lambda ud, req: {"a": 10, "b": 20}, bus=bus).execute(userdata())
    ServiceState("add", request={"a": 1, "b": 1}, request_cb=lambda ud, req: req.update(b=9), bus=bus).execute(userdata())
    assert requests == [{"a": 10, "b": 20}, {"a": 1, "b": 9}]


def test_request_cb_gets_its_args_and_sees_only_its_declared_keys(bus):
    add_service(bus)
    seen = []

    def request_cb(ud, req, scale, offset=0):
        seen.append(sorted(ud.keys()))
        return {"a": ud.x * scale, "b": offset}
    state = ServiceState("add", request_cb=request_cb, request_cb_args=[10], request_cb_kwargs={"offset": 3},
                         input_keys=["x"], response_slots=["sum"], bus=bus)
    ud = userdata(x=2, y=7)
    assert state.execute(ud) == "succeeded"
    assert seen == [["x"]] and ud.sum == 23


def test_request_cb_exception_aborts(bus, logs):
    add_service(bus)
    state = ServiceState("add", request_cb=lambda ud, req: 1 / 0, bus=bus)
    assert state.execute(userdata()) == "aborted"
    assert logs.error[0].startswith("Could not execute request callback: Traceback")


def test_service_handler_exception_aborts(bus, logs):
    bus.advertise_service("bad", lambda req: 1 / 0)
    assert ServiceState("bad", bus=bus).execute(userdata()) == "aborted"
    assert logs.error[0].startswith("Exception when calling service 'bad': ")


def test_response_slots_are_written_to_userdata(bus):
    add_service(bus)
    ud = userdata()
    assert ServiceState("add", request={"a": 2, "b": 2}, response_slots=["sum"], bus=bus).execute(ud) == "succeeded"
    assert ud.sum == 4


def test_response_cb_outcome_is_returned(bus):
    add_service(bus)

    @smach.cb_interface(outcomes=["big"])
    def response_cb(ud, response):
        return "big" if response.sum > 10 else None
    state = ServiceState("add", request={"a": 20, "b": 2}, response_cb=response_cb, bus=bus)
    assert state.execute(userdata()) == "big"


def test_unregistered_response_cb_outcome_aborts(bus, logs):
    add_service(bus)
    state = ServiceState("add", request={"a": 1, "b": 2}, response_cb=lambda ud, resp: "weird", bus=bus)
    assert state.execute(userdata()) == "aborted"
    assert "was not registered with the response_cb_outcomes argument" in logs.error[0]
    assert "returned 'weird'" in logs.error[0]


def test_response_cb_exception_aborts(bus, logs):
    add_service(bus)
    state = ServiceState("add", request={"a": 1, "b": 2}, response_cb=lambda ud, resp: 1 / 0, bus=bus)
    assert state.execute(userdata()) == "aborted"
    assert logs.error[0].startswith("Could not execute response callback: ")


def test_callback_that_is_not_callable_is_refused(bus):
    with pytest.raises(smach.InvalidStateError, match="Request callback object given to ServiceState"):
        ServiceState("add", request_cb="not a function", bus=bus)


def test_preempt_before_execute_gives_preempted_without_calling(bus, logs):
    requests = add_service(bus)
    state = ServiceState("add", request={"a": 1, "b": 2}, bus=bus)
    state.request_preempt()
    assert state.execute(userdata()) == "preempted"
    assert not state.preempt_requested() and requests == []
    assert "Preempting add before sending request." in logs.info


def test_waits_for_a_service_that_comes_up_later(bus):
    threading.Timer(0.05, add_service, (bus,)).start()
    state = ServiceState("add", request={"a": 1, "b": 2}, bus=bus)
    assert state.execute(userdata()) == "succeeded"


def test_preempt_while_waiting_for_the_service_gives_preempted_at_once(bus, logs):
    state = ServiceState("missing", bus=bus)
    run = Background(lambda: state.execute(userdata()))
    wait_for(lambda: logs.warn)
    t0 = time.monotonic()
    state.request_preempt()
    assert run.join(1.0) == "preempted"
    assert time.monotonic() - t0 < 0.5
    assert "Still waiting for service 'missing'..." in logs.warn
    assert "Preempting while waiting for service 'missing'." in logs.info


def test_shutdown_while_waiting_for_the_service_aborts(bus, logs):
    smach.set_shutdown_check(lambda: True)
    assert ServiceState("missing", bus=bus).execute(userdata()) == "aborted"
    assert "Terminated while waiting for service 'missing'." in logs.warn


def test_in_a_state_machine_slots_go_through_remapping(bus, logs):
    add_service(bus)
    sm = machine(["succeeded", "aborted", "preempted"],
                 [("ADD", ServiceState("add", request_slots=["a", "b"], response_slots=["sum"], bus=bus),
                   {}, {"a": "x", "sum": "total"})])
    sm.userdata.x = 3
    sm.userdata.b = 4
    assert sm.execute() == "succeeded"
    assert sm.userdata.total == 7


def test_uses_the_default_bus_when_none_is_given():
    handle = default_bus.advertise_service("default_add", lambda req: "ok")
    try:
        ud = userdata()
        assert ServiceState("default_add", response_key="r").execute(ud) == "succeeded"
        assert ud.r == "ok"
    finally:
        handle.shutdown()
