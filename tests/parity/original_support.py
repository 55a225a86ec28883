"""Machines written once for any implementation (``side.sm``: the original SMACH or fsm), and a run of
one watched or not, for the tests that compare a watched machine of the original SMACH with the same
machine unwatched, and with the same machine on fsm.

Each scenario builds its machine from ``side.sm``'s classes, runs it and returns what a user sees of
the run: the outcome (or the exception), the root's final userdata. A Concurrence's children wait on
each other's lines (``side.when_logged``) so that their lines come in one order on every run.
"""

import threading
from typing import Any, Callable

import fsm
from fsm.logfiles.recorder import Recorder

from parity_support import Side, kit, normalised, outcome_of


def loop(side: Side) -> Any:
    """The tutorial's two-state loop: FOO counts in userdata, BAR sends it back, three times round."""
    sm, k = side.sm, kit(side.sm)

    def foo(ud):
        ud.counter = ud.counter + 1
        sm.loginfo("Executing state FOO (%d)" % ud.counter)
        return "outcome1" if ud.counter < 3 else "outcome2"

    built = k.machine(["outcome4"], [
        ("FOO", k.Out(foo, outcomes=["outcome1", "outcome2"], input_keys=["counter"], output_keys=["counter"]),
         {"outcome1": "BAR", "outcome2": "outcome4"}),
        ("BAR", k.Out("outcome1"), {"outcome1": "FOO"})])
    built.userdata.counter = 0
    return built


def nested(side: Side) -> Any:
    """Three levels: ROOT > WORK (retries TRY until it has counted to the goal, through a remapped key)
    > PAR, a Concurrence of LEFT (a machine of its own, writing the result) and RIGHT."""
    sm, k = side.sm, kit(side.sm)

    def prepare(ud):
        ud.count = 0
        return "done"

    def attempt(ud):
        ud.n = ud.n + 1
        if ud.n < ud.goal:
            sm.logwarn("attempt %d of %d failed, retrying" % (ud.n, ud.goal))
            return "retry"
        return "ok"

    def calc(ud):
        ud.result = ud.count * 10
        return "done"

    left_done = side.when_logged("Concurrent state 'LEFT' returned")
    left = k.machine(["done"], [("CALC", k.Out(calc, input_keys=["count"], output_keys=["result"]), {})],
                     input_keys=["count"], output_keys=["result"])
    par = k.concurrence(["ok", "failed"], "failed", [
        ("LEFT", left), ("RIGHT", k.Out(lambda ud: left_done.wait(5) and "done"))],
        outcome_map={"ok": {"LEFT": "done", "RIGHT": "done"}}, input_keys=["count"], output_keys=["result"])
    work = k.machine(["ok", "failed"], [
        ("TRY", k.Out(attempt, outcomes=["retry", "ok"], input_keys=["n", "goal"], output_keys=["n"]),
         {"retry": "TRY", "ok": "PAR"}, {"n": "count"}),
        ("PAR", par, {"ok": "ok", "failed": "failed"})],
        input_keys=["goal", "count"], output_keys=["count", "result"])
    built = k.machine(["succeeded", "aborted"], [
        ("PREP", k.Out(prepare, output_keys=["count"]), {"done": "WORK"}),
        ("WORK", work, {"ok": "succeeded", "failed": "aborted"})])
    built.userdata.goal = 3
    return built


def raising(side: Side) -> Any:
    """ROOT > SUB > BAD, which raises ValueError('boom') after a state that wrote userdata."""
    k = kit(side.sm)

    def bad(ud):
        raise ValueError("boom")

    def write(ud):
        ud.x = 1
        return "done"

    sub = k.machine(["done"], [("SET", k.Out(write, output_keys=["x"]), {"done": "BAD"}), ("BAD", k.Out(bad), {})])
    return k.machine(["done"], [("SUB", sub, {})])


def raising_child(side: Side) -> Any:
    """ROOT > CC, a Concurrence whose child BAD raises RuntimeError once GOOD has returned."""
    k = kit(side.sm)
    good_done = side.when_logged("Concurrent state 'GOOD' returned")

    def bad(ud):
        good_done.wait(5)
        raise RuntimeError("child failed")

    cc = k.concurrence(["done"], "done", [("GOOD", k.Out("done")), ("BAD", k.Out(bad))])
    return k.machine(["done"], [("CC", cc, {})])


def raising_grandchild(side: Side) -> Any:
    """ROOT > CC, a Concurrence whose child SUB, a machine, runs INNER, which raises once GOOD has returned."""
    k = kit(side.sm)
    good_done = side.when_logged("Concurrent state 'GOOD' returned")

    def inner(ud):
        good_done.wait(5)
        raise RuntimeError("grandchild failed")

    sub = k.machine(["done"], [("INNER", k.Out(inner), {})])
    cc = k.concurrence(["done"], "done", [("GOOD", k.Out("done")), ("SUB", sub)])
    return k.machine(["done"], [("CC", cc, {})])


def preempted(side: Side) -> Any:
    """ROOT > SUB > WAIT, which blocks until preempted; the root is preempted once WAIT runs."""
    k = kit(side.sm)
    wait = k.WaitForPreempt(outcomes=["preempted", "timeout"])
    sub = k.machine(["preempted", "timeout"], [("WAIT", wait, {})])
    built = k.machine(["preempted", "timeout"], [("SUB", sub, {})])
    threading.Thread(target=lambda: wait.started.wait(5) and built.request_preempt(), daemon=True).start()
    return built


def preempted_concurrence(side: Side) -> Any:
    """ROOT > CC, a Concurrence of two states waiting for their preempt; the root is preempted once both run."""
    k = kit(side.sm)
    left_done = side.when_logged("Concurrent state 'LEFT' returned")

    class ThenWait(k.WaitForPreempt):
        """Returns once preempted and LEFT has returned, so that their lines come in one order."""

        def execute(self, ud):
            outcome = k.WaitForPreempt.execute(self, ud)
            left_done.wait(5)
            return outcome

    left, right = k.WaitForPreempt(), ThenWait()
    cc = k.concurrence(["done", "preempted"], "done", [("LEFT", left), ("RIGHT", right)])
    built = k.machine(["done", "preempted"], [("CC", cc, {})])
    threading.Thread(target=lambda: left.started.wait(5) and right.started.wait(5) and built.request_preempt(),
                     daemon=True).start()
    return built


def iterated(side: Side) -> Any:
    """ROOT > EACH, an Iterator over three items whose contained state sums them, and stops at 'big'."""
    sm, k = side.sm, kit(side.sm)

    def add(ud):
        ud.total = ud.total + ud.item
        return "big" if ud.total > 4 else "next"

    each = sm.Iterator(outcomes=["big", "exhausted"], input_keys=["total"], output_keys=["total"],
                       it=[1, 2, 3], it_label="item", exhausted_outcome="exhausted")
    with each:
        sm.Iterator.set_contained_state("ADD", k.Out(add, outcomes=["next", "big"], input_keys=["item", "total"],
                                                     output_keys=["total"]), loop_outcomes=["next"])
    built = k.machine(["big", "exhausted"], [("EACH", each, {})])
    built.userdata.total = 0
    return built


SCENARIOS: dict[str, Callable[[Side], Any]] = {
    "loop": loop, "nested": nested, "raising": raising, "raising_child": raising_child,
    "raising_grandchild": raising_grandchild, "preempted": preempted,
    "preempted_concurrence": preempted_concurrence, "iterated": iterated}
# Where two threads log at once: the original's Concurrence wakes as its child raises, and logs that
# it preempts the others while the child's thread words the exception. Their lines are compared in
# any order.
RACY = {"raising_child", "raising_grandchild"}


def lines(seen: dict, scenario: str) -> list:
    """The lines logged in a run, in order (sorted for a RACY scenario)."""
    return sorted(seen["logs"]) if scenario in RACY else seen["logs"]


def userdata_of(machine: Any) -> dict:
    """A machine's userdata as a dict of its values (fsm's and the original's keep them in ``_data``)."""
    return dict(object.__getattribute__(machine.userdata, "_data"))


def run(sm: Any, scenario: Callable[[Side], Any], log: Any = None) -> dict:
    """``scenario`` on ``sm`` (a ``smach`` module), watched when ``log`` is given (attached with a
    Recorder writing ``log`` and a list of its events): what a user sees of the run, normalised
    (outcome, the root's final userdata, the lines logged, the exceptions that ended a thread),
    and the events."""
    side = Side(sm)
    errors: list = []
    hook = threading.excepthook
    threading.excepthook = lambda args: errors.append((args.exc_type.__name__, str(args.exc_value)))
    events: list = []
    try:
        machine = scenario(side)
        side.logs.clear()  # the lines of construction come before anything is watched
        if log is None:
            outcome = outcome_of(machine.execute)
        else:
            with Recorder(log, new=True) as recorder:
                fsm.attach(machine, recorder, name="m")
                fsm.attach(machine, events.append)
                outcome = outcome_of(machine.execute)
    finally:
        threading.excepthook = hook
    seen = normalised({"outcome": outcome, "userdata": userdata_of(machine), "logs": side.logs,
                       "thread_errors": errors})
    return dict(seen, events=events)
