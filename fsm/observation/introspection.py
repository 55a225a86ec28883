"""Turns a running machine into a stream of events (docs/events.md) for any number of observers.

``Reporter`` implements core's reporting seam (``fsm.core.reporting.Reporter``): core calls one
method per kind with plain values, and the reporter encodes them, makes the event with the schema's
maker of that kind (``schema.build``) and stamps it (a step's event is made and its seq stamped when
it is delivered: ``Reporter.transition``, ``Reporter.deliver``). A machine nobody observes pays one
``is None`` test per step: containers check their ``_reporter`` attribute, which stays None until
``attach`` binds the tree.

One piece because stamping, delivering and folding an event, and describing the tree the events
refer to, share one reporter's lock, sequence and run.
"""

from __future__ import annotations

import functools
import inspect
import sys
import threading
import traceback
import uuid
from threading import get_ident
from time import time as _now
from typing import Any, Callable

from ..core import log, reporting
from ..core.reporting import add_global_hook, remove_global_hook  # noqa: F401 (their public path)
from . import names, schema
from .delivery import INLINE_BATCH, Batch, BatchObserver, delivery
from .encoding import encode_userdata, encode_written
from .schema import ABSENT, MAX_DOC, build, build_batch
from .status import Status
from .structure import children, is_container

DEFAULT_ROOT_PATH = "/SM_ROOT"

Observer = Callable[[dict], None]

_listening: set[Reporter] = set()
_listening_lock = threading.Lock()


def _never_raising(call: Callable[..., None]) -> Callable[..., None]:
    """One of core's calls on the reporter, made unable to fail: observing never changes what a
    machine does, so what goes wrong in it is said once (``Reporter._failed``) and goes no further."""
    what = "observing (%s)" % call.__name__

    @functools.wraps(call)
    def observed(self: Reporter, *args: Any) -> None:
        try:
            call(self, *args)
        except Exception:
            self._failed(call, what)
    return observed


def _words(exc: BaseException) -> str:
    """``str(exc)``, or what traceback writes when a user's exception cannot say it."""
    try:
        return str(exc)
    except Exception:
        return "<exception str() failed>"


class Reporter:
    """Stamps one machine's events (seq, time, run) and hands them to its observers in order: to each
    plain observer at once, in the thread that made the event, and to the observers that take
    batches (``take_batch``: the recorder, the dashboard's hub) on the delivery thread
    (fsm/observation/delivery.py), after folding them into the machine's ``Status`` when an
    observer asked for one (``folded_status``)."""

    def __init__(self, root: Any, machine: str, root_path: str = DEFAULT_ROOT_PATH) -> None:
        self.root = root
        self.machine = machine
        self.root_path = root_path
        self.run: str | None = None
        self._seq = 0
        self._observers: list[Observer] = []  # called with each event, in ``send``
        self._batched: list[BatchObserver] = []  # given each batch, in ``deliver``
        # Made, not delivered yet, in order: events, and a step's record (``transition``) that ``deliver`` makes
        # its event of; their seqs follow ``_seq`` in this order. None: nobody takes batches or folds.
        self._pending: list[dict | tuple] | None = None
        self._queued = False  # the delivery thread was told of the pending list since it last took it
        self._lock = threading.Lock()  # guards the seq, and the pending list when plain observers listen or it is taken
        self._delivering = threading.RLock()  # one batch at a time; guards the Status
        self._owner: int | None = None  # the thread calling the plain observers right now
        self._described_at = -1  # the construction generation of the last structure event
        self._told: list[Observer] = []  # the observers whose failure was printed
        self._status: Status | None = None  # folded in ``deliver`` once an observer asked for it
        self.inline = 0  # events delivered in the machine's own thread since the delivery thread last looked

    @property
    def last_seq(self) -> int:
        """The seq of the last event made (delivered or not)."""
        pending = self._pending
        return self._seq + (len(pending) if pending else 0)

    @property
    def listening(self) -> bool:
        """Whether an event sent now goes anywhere (an observer, or the Status folded)."""
        return bool(self._observers) or self._pending is not None

    def folded_status(self) -> tuple[Status, threading.RLock]:
        """The machine's ``Status``, from now on folded once per event as the events are delivered,
        before any observer that takes batches sees them, and the lock to hold to read it or change
        it from another thread (a batch's observer holds it already). One fold for every reader that
        needs one (the recorder's snapshots, the dashboard's page, a robot's state queries): a
        machine whose observers need none pays nothing for it. Holding the lock, ``deliver`` brings
        it up to the events made so far."""
        with self._delivering:
            if self._status is None:
                self._status = Status(self.machine)
                self._take_batches()
            return self._status, self._delivering

    def add_observer(self, observer: Observer | BatchObserver) -> None:
        """An observer with a ``take_batch`` method is given batches (fsm/observation/delivery.py);
        any other is called with each event. One with an ``attached(reporter)`` method is then given
        this reporter: one that acts on the machine too (a publisher that takes controls from afar)
        reaches it as ``reporter.root``."""
        # Replaced, never mutated: send and deliver iterate the lists they read without the lock.
        if callable(getattr(observer, "take_batch", None)):
            with self._delivering:
                self._batched = self._batched + [observer]
                self._take_batches()
        else:
            self._observers = self._observers + [observer]
        self._described_at = -1  # the newcomer has not seen the structure
        _set_listening(self, True)
        attached = getattr(observer, "attached", None)
        if callable(attached):
            attached(self)

    def remove_observer(self, observer: Observer | BatchObserver) -> None:
        """A batch's observer is first given what was made before (``deliver``)."""
        # Equality, not identity: ``remove_observer(events.append)`` must match the bound method given to attach.
        if any(o == observer for o in self._batched):
            with self._delivering:
                self.deliver()
                self._batched = [o for o in self._batched if o != observer]
        self._observers = [o for o in self._observers if o != observer]
        if not self._observers and not self._batched:
            _set_listening(self, False)

    def _take_batches(self) -> None:
        with self._lock:
            if self._pending is None:
                self._pending = []

    def send(self, make: Callable[..., dict], path: str | None, *args: Any) -> dict | None:
        """Stamp ``make(seq, t, run, machine, path, *args)`` (a maker of ``schema.build``) and deliver it;
        returns it (None when nobody listens). What someone may act on as soon as it happens (a root's
        termination, an error, a preempt, a control, the debugger's holds) is delivered before this
        returns, with every event made before it."""
        observers = self._observers
        pending = self._pending
        if not observers:
            if pending is None:
                return None
            return self._pend(make(0, _now(), self.run, self.machine, path, *args))
        me = get_ident()
        if self._owner == me:  # an observer logged: do not recurse into ourselves
            return None
        waiting = 0
        with self._lock:
            if pending is None:
                self._seq = seq = self._seq + 1
            else:
                seq = self._seq + len(pending) + 1
            event = make(seq, _now(), self.run, self.machine, path, *args)
            if pending is not None:
                pending.append(event)
                waiting = len(pending)
                if not self._queued:
                    self._queue()
            self._owner = me
            for observer in observers:
                try:
                    observer(event)
                except Exception:
                    self._failed(observer)
            self._owner = None
        if waiting >= INLINE_BATCH or event["kind"] in _AT_ONCE:
            self._deliver_now(event, waiting)
        return event

    def _pend(self, event: dict) -> dict:
        """``send`` when only observers of batches listen: the event, made with a placeholder seq, joins
        the pending list with no lock (an append is one step under the GIL); ``deliver`` stamps its seq."""
        pending = self._pending
        pending.append(event)
        if not self._queued:
            self._queue()
        waiting = len(pending)
        if waiting >= INLINE_BATCH or event["kind"] in _AT_ONCE:
            self._deliver_now(event, waiting)
        return event

    def _queue(self) -> None:
        """Tell the delivery thread of the pending list (``deliver`` clears the flag before it takes it, so
        an event that misses a batch is told of again; told twice, the thread finds nothing the second time)."""
        self._queued = True
        delivery.ready(self)

    def _deliver_now(self, event: dict, waiting: int) -> None:
        """Deliver in this thread what a busy machine has waiting (``INLINE_BATCH``: with no hand-over
        of the GIL to the delivery thread) and what someone acts on at once (``_AT_ONCE``)."""
        if waiting >= INLINE_BATCH:
            self.inline += self.deliver()
        elif (event["kind"] != "terminate" or event["path"] == self.root_path) and self._pending:
            self.deliver()

    def deliver(self) -> int:
        """Make the events of the steps recorded so far, stamp the seqs of all of them in the order they
        were made, fold them and hand them to the observers that take batches, now, in this thread;
        returns how many. The delivery thread calls it; so does a root's termination, and an
        observer leaving or closing, so that it is given everything made before. A batch ends at the
        seq an observer wants the Status after (``next_cut``: the recorder's next snapshot)."""
        with self._delivering:
            with self._lock:
                pending = self._pending
                if not pending:
                    return 0
                self._queued = False  # before it is taken: what a machine's thread appends after is told again
                taken = len(pending)
                first = self._seq + 1
                made = pending[:taken]
                del pending[:taken]  # not replaced: a machine's thread may be appending to it without the lock
                self._seq += taken
            events = build_batch(first, made)
            start = 0
            while start < len(events):
                end = len(events)
                for observer in self._batched:
                    cut = observer.next_cut(self.machine) if hasattr(observer, "next_cut") else None
                    if cut is not None and first + start <= cut < first + end - 1:
                        end = cut - first + 1
                self._deliver(events[start:end] if start or end < len(events) else events)
                start = end
            return len(events)

    def _deliver(self, events: list[dict]) -> None:
        status = self._status
        if status is not None:
            try:
                status.apply_all(events)
            except Exception:  # said once; the events after the one that failed are folded one by one
                self._failed(status, "folding the Status")
                for event in events:
                    if event["seq"] > status.last_seq:
                        try:
                            status.apply(event)
                        except Exception:
                            pass
        batch = Batch(self.machine, events, status)
        for observer in self._batched:
            try:
                observer.take_batch(batch)
            except Exception:
                self._failed(observer)

    # Core's calls (fsm.core.reporting.Reporter), one per kind; those that do more than send (encode a
    # value, describe the tree, word an exception) are ``_never_raising``.
    @_never_raising
    def start(self, path: str, initial: list[str], active: list[str], userdata: Any) -> None:
        self.send(_start, path, initial, active, encode_userdata(userdata._data))

    def transition(self, path: str, from_: str, outcome: str, to: str | None, active: list[str],
                   changes: dict | None = None) -> None:
        written = self._encoded(changes) if changes else ABSENT
        pending = self._pending
        if self._observers or pending is None:
            self.send(_transition, path, from_, outcome, to, active, written)
            return
        # The hot path of every observed step: a record of ``_transition``'s arguments but the seq (``deliver``).
        pending.append((_now(), self.run, self.machine, path, from_, outcome, to, active, written))
        if not self._queued:
            self._queue()
        if len(pending) >= INLINE_BATCH:
            self.inline += self.deliver()

    def terminate(self, path: str, last: list[str], outcome: str | None, active: list[str] = ABSENT,
                  state_outcome: str | None = ABSENT, outcomes: dict = ABSENT, error: str | None = ABSENT,
                  changes: dict | None = None) -> None:
        self.send(_terminate, path, last, outcome, active, state_outcome, outcomes, error,
                  self._encoded(changes) if changes else ABSENT)

    @_never_raising
    def userdata(self, path: str, written: dict) -> None:
        self.send(_userdata, path, encode_userdata(written))

    def _encoded(self, changes: dict) -> dict:
        """The keys a step wrote, with their values (a dict of ``UserData.take_written``'s, nobody else's),
        encoded (its event's ``changes``); what cannot be encoded is said once and the event goes without
        them: a transition is never lost to its userdata."""
        try:
            return encode_written(changes)
        except Exception:
            self._failed(encode_userdata, "observing (userdata)")  # a stable identity: said once
            return ABSENT

    def preempt(self, path: str, phase: str) -> None:
        self.send(_preempt, path, phase)

    @_never_raising
    def error(self, path: str, state: Any, exc: BaseException) -> None:
        """Describe the root cause (the user's own exception), not SMACH's wrapper around it."""
        root = exc
        while root.__cause__ is not None:
            root = root.__cause__
        self.send(_error, path, None if state is None else str(state), type(root).__name__, _words(root),
                   "".join(traceback.format_exception(type(exc), exc, exc.__traceback__)),
                   type(exc).__name__ if root is not exc else ABSENT)

    def _failed(self, observer: Any, what: str = "an observer") -> None:
        """An observer (or the reporter's own work for one of core's calls) could not take an event:
        said once per observer (with why), not per event, since one that fails once usually fails on
        every event that follows."""
        if any(o is observer for o in self._told):
            return
        self._told.append(observer)
        sys.stderr.write("fsm: %s of machine %r failed (its next failures are not printed):\n%s"
                         % (what, self.machine, traceback.format_exc()))

    @_never_raising
    def begin_run(self) -> None:
        """Called by the root container as it starts: a new run id, then the structure if it
        changed since it was last sent (or an observer joined since)."""
        self.run = uuid.uuid4().hex[:12]
        generation = reporting.structure_generation()
        if self._described_at != generation:
            self._described_at = generation
            self.send(build.structure, self.root_path, self.structure())

    def structure(self) -> dict:
        """Bind every state of the tree to this reporter and describe the tree (docs/events.md)."""
        label = self.root_path.rstrip("/").rsplit("/", 1)[-1] or "SM_ROOT"
        return _describe(self.root, label, self.root_path, self, {})


_OWN_PACKAGES = ("fsm", "smach", "smach_ros")  # whose classes' docstrings are SMACH's, not the task's


@functools.lru_cache(maxsize=1024)
def class_doc(cls: type) -> str | None:
    """The first paragraph of a class's own docstring, on one line, at most MAX_DOC characters: what a
    user's state does, for the page's details. None for fsm's own classes and the original SMACH's
    (the same text in every node would say nothing of the task) and a class without one (a
    docstring is never inherited)."""
    doc = cls.__dict__.get("__doc__")
    if not isinstance(doc, str) or cls.__module__.split(".")[0] in _OWN_PACKAGES:
        return None
    first = " ".join(inspect.cleandoc(doc).split("\n\n")[0].split())
    if not first:
        return None
    return first if len(first) <= MAX_DOC else first[:MAX_DOC - 1] + "…"


def describe_node(state: Any, label: str, path: str, remapping: dict,
                  describe_child: Callable[[Any, str, str, dict], dict]) -> dict:
    """The ``structure`` event's node of ``state``, as every runtime reads it through SMACH's
    interface; a container's children are described by ``describe_child(child, label, path,
    remapping)`` (each runtime binds its observer to the states it visits)."""
    doc = class_doc(type(state))
    container = is_container(state)
    node = schema.node(label, path, type(state).__name__, container, sorted(map(str, state.get_registered_outcomes())),
                       sorted(map(str, state.get_registered_input_keys())),
                       sorted(map(str, state.get_registered_output_keys())),
                       {str(k): str(v) for k, v in (remapping or {}).items()}, ABSENT if doc is None else doc)
    if not container:
        return node
    remappings = getattr(state, "_remappings", None) or {}
    node.update(schema.container_fields(
        [str(s) for s in state.get_initial_states()],
        [schema.edge(str(frm), str(outcome), None if to is None else str(to))
         for outcome, frm, to in state.get_internal_edges()],
        [describe_child(child, str(lbl), path + "/" + str(lbl), remappings.get(lbl, {}))
         for lbl, child in children(state).items()]))
    return node


def _describe(state: Any, label: str, path: str, rep: Reporter, remapping: dict) -> dict:
    state._reporter = rep
    state._path = path
    if is_container(state) and state.userdata._dirty is None:
        state.userdata.track_writes()
    node = describe_node(state, label, path, remapping,
                         lambda child, lbl, at, remap: _describe(child, lbl, at, rep, remap))
    if node["container"]:
        node.update(state._introspection_info())
    return node


# The reporters of machines of another runtime: ``make(machine, name, path)`` gives one bound to the
# machine, or None when the machine is not of that runtime. fsm/observation/original.py registers the
# original SMACH's (fsm/observation/__init__.py imports it, so it is registered wherever attach is).
foreign_reporters: list[Callable[[Any, str, str], Reporter | None]] = []


def attach(machine: Any, observer: Observer | None = None, name: str | None = None,
           path: str = DEFAULT_ROOT_PATH) -> Reporter:
    """Observe a top-level container, of fsm or of the original SMACH (fsm/observation/original.py);
    a second call adds an observer to the same reporter. ``name`` must keep the name rule
    (fsm/observation/names.py: ValueError saying why); without one the machine is named after its
    root path."""
    rep = getattr(machine, "_reporter", None)
    if rep is None or rep.root is not machine:
        name = names.check(name) if name else names.valid(path.rsplit("/", 1)[-1] or "SM_ROOT")
        rep = next(filter(None, (make(machine, name, path) for make in foreign_reporters)), None)
        if rep is None:
            rep = Reporter(machine, name, path)
            machine._reporter = rep
            machine._path = path
            rep.structure()
    if observer is not None:
        rep.add_observer(observer)
    return rep


def reporter_of(machine: Any) -> Reporter | None:
    # Never through ``machine.__dict__``: reading an instance's __dict__ makes CPython 3.11 keep its
    # attributes in a real dict from then on, and every attribute read of every step slows down
    # (bench/debugger.py measured -30 % on the two-state loop).
    rep = getattr(machine, "_reporter", None)
    return rep if rep is not None and rep.root is machine else None


def _on_log(level: str, msg: str) -> None:
    ctx = reporting.current()
    if ctx is not None:
        ctx[0].send(_log, ctx[1], level, msg)


def _set_listening(rep: Reporter, on: bool) -> None:
    with _listening_lock:
        (_listening.add if on else _listening.discard)(rep)
        log.listener = _on_log if _listening else None


# The kinds delivered in the thread that made them (``send``): rare, and read at once by whoever acts on them.
_AT_ONCE = frozenset(("terminate", "error", "preempt", "control", "debug"))

# The makers of the kinds core reports, bound once.
_start, _transition, _terminate, _userdata = build.start, build.transition, build.terminate, build.userdata
_preempt, _error, _log = build.preempt, build.error, build.log
