"""Events handed to the observers that take batches (fsm/observation/delivery.py): in order, at once
for a machine that steps now and then, before ``execute`` returns for a run, cut where an observer
wants the Status, past an observer that fails, and in a process made by fork."""

import os
import threading

import fsm
from fsm.observation.schema import build
from fsmscope.server.testing.polling import wait_for

from smach_support import counting_machine


class Taking:
    """An observer of batches: every event it was given, and the batches' sizes."""

    def __init__(self, cut_every: int | None = None) -> None:
        self.events: list[dict] = []
        self.sizes: list[int] = []
        self.cut_every = cut_every

    def take_batch(self, batch) -> None:
        self.events.extend(batch.events)
        self.sizes.append(len(batch.events))

    def next_cut(self, machine: str) -> int | None:
        if self.cut_every is None:
            return None
        last = self.events[-1]["seq"] if self.events else 0
        return last + self.cut_every


def log_line(rep, text: str) -> dict:
    return rep.send(build.log, rep.root_path, "info", text)


def test_an_event_of_a_quiet_machine_reaches_a_batch_observer_without_waiting_for_its_run_to_end():
    taking = Taking()
    rep = fsm.attach(counting_machine(3), taking, name="quiet")
    sent = log_line(rep, "now")
    wait_for(lambda: taking.events, timeout=5, what="the event delivered")
    assert taking.events == [sent]


def test_a_run_is_with_every_batch_observer_when_execute_returns():
    taking, plain = Taking(), []
    sm = counting_machine(50)
    fsm.attach(sm, taking, name="run")
    fsm.attach(sm, plain.append)
    sm.execute()
    assert [e["seq"] for e in taking.events] == [e["seq"] for e in plain]
    assert taking.events[-1]["kind"] == "terminate"


def test_events_from_several_threads_reach_the_observer_in_seq_order():
    taking = Taking()
    rep = fsm.attach(counting_machine(3), taking, name="threads")
    threads = [threading.Thread(target=lambda: [log_line(rep, "x") for _ in range(200)]) for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    rep.deliver()
    assert [e["seq"] for e in taking.events] == list(range(1, 801))


def test_a_batch_ends_where_an_observer_wants_the_status():
    taking = Taking(cut_every=10)
    sm = counting_machine(40)
    fsm.attach(sm, taking, name="cut")
    sm.execute()
    assert max(taking.sizes) <= 10 and sum(taking.sizes) == len(taking.events)


def test_an_observer_that_raises_leaves_the_machine_and_the_other_observers_going(capsys):
    class Failing:
        def take_batch(self, batch):
            raise RuntimeError("broken observer")

    taking = Taking(cut_every=5)  # several batches, each failing
    sm = counting_machine(20)
    fsm.attach(sm, Failing(), name="failing")
    fsm.attach(sm, taking)
    assert sm.execute() == "done"
    assert taking.events[-1]["kind"] == "terminate" and len(taking.sizes) > 1
    assert capsys.readouterr().err.count("RuntimeError: broken observer") == 1  # said once, not per batch


def test_a_machine_in_a_process_made_by_fork_has_its_events_delivered_there():
    taking = Taking()
    rep = fsm.attach(counting_machine(3), taking, name="forked")
    log_line(rep, "before")
    wait_for(lambda: taking.events, timeout=5, what="the parent's event delivered")
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: a quiet machine's event, delivered by a delivery thread of its own
        taking.events.clear()
        log_line(rep, "in the child")
        try:
            wait_for(lambda: taking.events, timeout=5, what="the child's event delivered")
            os.write(write, taking.events[0]["msg"].encode())
        finally:
            os._exit(0)
    os.close(write)
    said = os.read(read, 100).decode()
    os.waitpid(pid, 0)
    assert said == "in the child"
