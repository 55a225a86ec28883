"""fsm.ros.bus: topics, services and waits, with real threads."""

import threading
import time

import pytest

from fsm.ros.bus import ServiceException, default_bus, get_bus


def test_publish_reaches_every_subscriber_of_the_topic_only(bus):
    got_a, got_b, got_other = [], [], []
    bus.subscribe("t", got_a.append)
    bus.subscribe("t", got_b.append)
    bus.subscribe("other", got_other.append)
    bus.publish("t", 1)
    assert (got_a, got_b, got_other) == ([1], [1], [])


def test_publish_without_subscribers_does_nothing_and_returns_0(bus):
    assert bus.publish("nobody", {"x": 1}) == 0
    assert bus.topics() == []


def test_publish_returns_the_number_of_subscribers_reached(bus, logs):
    bus.subscribe("t", lambda msg: None)
    bus.subscribe("t", lambda msg: 1 / 0)  # reached, though it raised
    bus.subscribe("other", lambda msg: None)
    assert bus.publish("t", None) == 2


def test_raising_subscriber_is_logged_and_does_not_stop_the_others(bus, logs):
    got = []
    bus.subscribe("t", lambda msg: 1 / 0)
    bus.subscribe("t", got.append)
    bus.publish("t", "m")
    assert got == ["m"]
    assert len(logs.error) == 1
    assert "subscriber callback on topic 't'" in logs.error[0] and "ZeroDivisionError" in logs.error[0]


def test_unregister_stops_delivery_and_can_be_repeated(bus):
    got = []
    sub = bus.subscribe("t", got.append)
    sub.unregister()
    sub.unregister()
    bus.publish("t", 1)
    assert got == []


def test_topics_lists_topics_that_have_subscribers(bus):
    sub = bus.subscribe("b", print)
    bus.subscribe("a", print)
    assert bus.topics() == ["a", "b"]
    sub.unregister()
    assert bus.topics() == ["a"]


def test_call_service_returns_the_handler_response(bus):
    bus.advertise_service("add", lambda req: req["a"] + req["b"])
    assert bus.call_service("add", {"a": 1, "b": 2}) == 3
    assert bus.services() == ["add"]


def test_call_service_that_nobody_offers_raises_service_exception(bus):
    with pytest.raises(ServiceException, match="'missing' is not available"):
        bus.call_service("missing", {})


def test_call_service_whose_handler_raises_raises_service_exception(bus):
    bus.advertise_service("bad", lambda req: 1 / 0)
    with pytest.raises(ServiceException, match="ZeroDivisionError") as info:
        bus.call_service("bad", None)
    assert isinstance(info.value.__cause__, ZeroDivisionError)


def test_call_service_waits_up_to_its_timeout_for_the_service(bus):
    threading.Timer(0.05, bus.advertise_service, ("late", lambda req: "ok")).start()
    assert bus.call_service("late", None, timeout=1.0) == "ok"


def test_service_shutdown_withdraws_it(bus):
    handle = bus.advertise_service("s", lambda req: req)
    handle.shutdown()
    assert bus.services() == []
    assert not bus.wait_for_service("s", timeout=0)


def test_a_service_name_can_be_advertised_once(bus):
    bus.advertise_service("s", lambda req: req)
    with pytest.raises(ValueError, match="already registered"):
        bus.advertise_service("s", lambda req: req)


def test_stale_handle_shutdown_leaves_the_new_service_alone(bus):
    old = bus.advertise_service("s", lambda req: "old")
    old.shutdown()
    bus.advertise_service("s", lambda req: "new")
    old.shutdown()
    assert bus.call_service("s", None) == "new"


def test_wait_for_service_returns_when_it_appears(bus):
    threading.Timer(0.05, bus.advertise_service, ("s", lambda req: req)).start()
    t0 = time.monotonic()
    assert bus.wait_for_service("s", timeout=2.0)
    assert time.monotonic() - t0 < 1.0


def test_wait_for_service_times_out(bus):
    t0 = time.monotonic()
    assert not bus.wait_for_service("s", timeout=0.05)
    assert 0.04 < time.monotonic() - t0 < 0.5


def test_wait_for_service_ends_early_when_woken(bus):
    wake = threading.Event()
    threading.Timer(0.05, wake.set).start()
    t0 = time.monotonic()
    assert not bus.wait_for_service("s", timeout=5.0, wake=wake)
    assert time.monotonic() - t0 < 1.0


def test_wait_for_action_server_returns_when_registered(bus):
    server = object()
    threading.Timer(0.05, bus.register_action_server, ("move", server)).start()
    assert bus.wait_for_action_server("move", timeout=2.0)
    assert bus.action_server("move") is server
    assert bus.action_servers() == ["move"]
    bus.unregister_action_server("move", server)
    assert bus.action_server("move") is None


def test_get_bus_gives_the_default_bus_or_the_one_passed(bus):
    assert get_bus() is default_bus
    assert get_bus(bus) is bus


def test_concurrent_publishers_lose_no_message(bus):
    got = []
    lock = threading.Lock()

    def on_msg(msg):
        with lock:
            got.append(msg)
    bus.subscribe("t", on_msg)
    threads = [threading.Thread(target=lambda k=k: [bus.publish("t", (k, i)) for i in range(200)]) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(got) == 800
