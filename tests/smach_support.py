"""Small states and builders shared by the SMACH acceptance tests (``import fsm as smach``)."""

import threading
from typing import Any, Callable

import fsm as smach
import pytest


class Out(smach.State):
    """Returns ``result`` (or ``result(ud)`` if callable: outcomes then default to ``["done"]``); counts its runs."""

    def __init__(self, result: Any = "done", outcomes: Any = None, input_keys: list = [],
                 output_keys: list = [], io_keys: list = []) -> None:
        if outcomes is None:
            outcomes = ["done"] if callable(result) else [result]
        smach.State.__init__(self, outcomes, input_keys, output_keys, io_keys)
        self.result = result
        self.runs = 0
        self.saw_preempt: list[bool] = []

    def execute(self, ud: Any) -> Any:
        self.runs += 1
        self.saw_preempt.append(self.preempt_requested())
        return self.result(ud) if callable(self.result) else self.result


class WaitForPreempt(smach.State):
    """Blocks until preempted (``started`` is set once it runs); services the preempt if told to."""

    def __init__(self, outcomes: Any = ("preempted",), service: bool = True, result: str = "preempted",
                 timeout: float = 5.0) -> None:
        smach.State.__init__(self, list(outcomes))
        self.started = threading.Event()
        self._preempt_event = threading.Event()
        self.service = service
        self.result = result
        self.timeout = timeout

    def request_preempt(self) -> None:
        smach.State.request_preempt(self)
        self._preempt_event.set()

    def execute(self, ud: Any) -> str:
        self.started.set()
        if not self._preempt_event.wait(self.timeout):
            return "timeout"
        self._preempt_event.clear()
        if self.service:
            self.service_preempt()
        return self.result


def machine(outcomes: list, children: list, **kwargs: Any) -> smach.StateMachine:
    """A StateMachine built from ``(label, state, transitions[, remapping])`` tuples."""
    sm = smach.StateMachine(outcomes=outcomes, **kwargs)
    with sm:
        for child in children:
            smach.StateMachine.add(*child)
    return sm


def concurrence(outcomes: list, default_outcome: str, children: list, **kwargs: Any) -> smach.Concurrence:
    """A Concurrence built from ``(label, state[, remapping])`` tuples."""
    cc = smach.Concurrence(outcomes=outcomes, default_outcome=default_outcome, **kwargs)
    with cc:
        for child in children:
            smach.Concurrence.add(*child)
    return cc


class Background:
    """Runs ``fn()`` in a thread; ``join()`` returns its result or re-raises its exception."""

    def __init__(self, fn: Callable[[], Any]) -> None:
        self.result: Any = None
        self.error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, args=(fn,), daemon=True)
        self._thread.start()

    def _run(self, fn: Callable[[], Any]) -> None:
        try:
            self.result = fn()
        except BaseException as exc:  # handed to the test thread
            self.error = exc

    def join(self, timeout: float = 5.0) -> Any:
        self._thread.join(timeout)
        assert not self._thread.is_alive(), "background execution did not finish"
        if self.error is not None:
            raise self.error
        return self.result


def preempt_while_running(container: Any, *waiting: WaitForPreempt, timeout: float = 5.0) -> Any:
    """Execute ``container`` in a thread and preempt it once every ``waiting`` state runs; returns its outcome."""
    run = Background(container.execute)
    for state in waiting:
        assert state.started.wait(timeout), "a state that should block never started"
    container.request_preempt()
    return run.join(timeout)


def userdata(**values: Any) -> smach.UserData:
    """A UserData holding ``values``."""
    ud = smach.UserData()
    ud.update(values)
    return ud


def failing_machine():
    """SM_ROOT: SUB(BAD raises ValueError) -> done."""
    def bad(ud):
        raise ValueError("boom")

    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        sub = smach.StateMachine(outcomes=["ok"])
        with sub:
            smach.StateMachine.add("BAD", smach.CBState(bad, outcomes=["go"]), {"go": "ok"})
        smach.StateMachine.add("SUB", sub, {"ok": "done"})
    return sm


def run_to_failure(sm):
    with pytest.raises(smach.SmachError):
        sm.execute()


def two_level_machine(first=None):
    """SM_ROOT: [FIRST ->] SUB(A -> B) -> done; B writes SUB's `x`. ``first``: a state run before SUB."""
    def write(ud):
        ud.x = ud.x + 1
        return "go"

    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        if first is not None:
            smach.StateMachine.add("FIRST", first, {"go": "SUB"})
        sub = smach.StateMachine(outcomes=["ok"])
        sub.userdata.x = 0
        with sub:
            smach.StateMachine.add("A", smach.CBState(lambda ud: "go", outcomes=["go"]), {"go": "B"})
            smach.StateMachine.add("B", smach.CBState(write, outcomes=["go"], input_keys=["x"], output_keys=["x"]),
                                   {"go": "ok"})
        smach.StateMachine.add("SUB", sub, {"ok": "done"})
    return sm


def one_state_machine(label: str, state: smach.State) -> smach.StateMachine:
    """SM_ROOT: ``label`` (``state``) -done-> done."""
    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add(label, state, {"done": "done"})
    return sm


def counting_machine(rounds: int) -> smach.StateMachine:
    """SM_ROOT: COUNT (n += 1) -> SUB (A -> B, each writing `trail`) -> COUNT ..., 'done' after ``rounds``
    (5 events a round: a long run of two levels with userdata, for history and recording tests)."""
    def count(ud: Any) -> str:
        ud.n = ud.n + 1
        return "again" if ud.n <= rounds else "enough"

    def mark(label: str) -> Out:
        def write(ud: Any) -> str:
            ud.trail = label
            return "done"
        return Out(write, output_keys=["trail"])

    sub = machine(["done"], [("A", mark("A"), {"done": "B"}), ("B", mark("B"), {"done": "done"})])
    sm = machine(["done"], [("COUNT", Out(count, outcomes=["again", "enough"], input_keys=["n"], output_keys=["n"]),
                             {"again": "SUB", "enough": "done"}),
                            ("SUB", sub, {"done": "COUNT"})])
    sm.userdata.n = 0
    return sm
