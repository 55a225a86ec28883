"""Every kind of machine takes its controls through one interface (fsm/control/controls.py), and says
what it cannot do in the words its refusal carries."""

from __future__ import annotations

import inspect

import fsm
import pytest
from fsm.control.controls import Controls, NoControls, Refused
from fsm.control.handle import MachineHandle

from fsmscope.server.remote_control import RemoteHandle

def members() -> list[str]:
    return sorted(name for name in vars(Controls) if not name.startswith("_"))


def one_state_machine() -> fsm.StateMachine:
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": "done"})
    return sm


def local() -> MachineHandle:
    sm = one_state_machine()
    return MachineHandle(sm, fsm.attach(sm, name="m"), can_start=True)


KINDS = {"local": local, "published": lambda: RemoteHandle("far"), "none": lambda: NoControls("why")}


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_every_kind_of_machine_has_every_control_with_the_protocols_parameters(kind):
    controls = KINDS[kind]()
    wrong = []
    for name in members():
        wanted, given = getattr(Controls, name), getattr(controls, name, None)
        if not hasattr(controls, name):
            wrong.append("%s is missing" % name)
        elif inspect.isfunction(wanted) and getattr(given, "__func__", None) is not NoControls._refuse:
            parameters = list(inspect.signature(wanted).parameters)[1:]  # without self
            if list(inspect.signature(given).parameters) != parameters:
                wrong.append("%s%s is not %s" % (name, inspect.signature(given), parameters))
    assert wrong == []


@pytest.mark.parametrize("action, call", [("start", lambda h: h.start("me")),
                                          ("hold", lambda h: h.hold(None, "me"))])
def test_a_control_a_machine_cannot_take_is_refused_in_the_words_of_its_capabilities(action, call):
    sm = one_state_machine()
    handle = MachineHandle(sm, fsm.attach(sm, name="m"), can_start=False)
    capabilities = handle.capabilities()
    assert not capabilities.can(action)
    with pytest.raises(Refused) as refused:
        call(handle)
    assert (refused.value.status, refused.value.message) == (409, capabilities.cannot[action])


def test_a_machine_run_in_a_loop_by_a_process_that_can_rerun_it_can_do_everything():
    sm = one_state_machine()
    handle = MachineHandle(sm, fsm.attach(sm, name="m"), can_start=True, holder=lambda: None)
    assert handle.capabilities().cannot == {} and handle.capabilities().unavailable is None


def test_a_published_machine_whose_process_is_away_takes_no_control_and_says_why():
    remote = RemoteHandle("far")
    unavailable = remote.capabilities().unavailable
    assert unavailable is not None and "not connected" in unavailable
    with pytest.raises(Refused) as refused:
        remote.pause("me")
    assert (refused.value.status, refused.value.message) == (409, unavailable)
