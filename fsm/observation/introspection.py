"""Turns a running machine into a stream of events (docs/events.md) for any number of observers.

A machine nobody observes pays one ``is None`` test per step: containers check their
``_reporter`` attribute, which stays None until ``attach`` binds the tree.
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

from ..core import log
from . import names
from .encoding import encode_userdata
from .schema import MAX_DOC, event as _event
from .structure import children, is_container

DEFAULT_ROOT_PATH = "/SM_ROOT"

Observer = Callable[[dict], None]
Hook = Callable[[Any], None]

_hooks: list[Hook] = []
# Bumped by every construction call anywhere: a structure described before it may be stale.
_generation = 0
_tls = threading.local()
_listening: set[Reporter] = set()
_listening_lock = threading.Lock()


class Reporter:
    """Stamps one machine's events (seq, time, run) and hands them to its observers in order."""

    def __init__(self, root: Any, machine: str, root_path: str = DEFAULT_ROOT_PATH) -> None:
        self.root = root
        self.machine = machine
        self.root_path = root_path
        self.run: str | None = None
        self._seq = 0
        self._observers: list[Observer] = []
        self._lock = threading.Lock()
        self._owner: int | None = None  # the thread delivering an event right now
        self._described_at = -1  # the construction generation of the last structure event
        self._told: list[Observer] = []  # the observers whose failure was printed

    @property
    def last_seq(self) -> int:
        return self._seq

    def add_observer(self, observer: Observer) -> None:
        """An observer with an ``attached(reporter)`` method is then given this reporter: one that acts
        on the machine too (a publisher that takes controls from afar) reaches it as ``reporter.root``."""
        # Replaced, never mutated: emit iterates the list it read without the lock.
        self._observers = self._observers + [observer]
        self._described_at = -1  # the newcomer has not seen the structure
        _set_listening(self, True)
        attached = getattr(observer, "attached", None)
        if callable(attached):
            attached(self)

    def remove_observer(self, observer: Observer) -> None:
        # Equality, not identity: ``remove_observer(events.append)`` must match the bound method given to attach.
        self._observers = [o for o in self._observers if o != observer]
        if not self._observers:
            _set_listening(self, False)

    def emit(self, kind: str, path: str | None, fields: dict | None = None) -> dict | None:
        """Stamp and deliver one event; returns it (None when nobody listens)."""
        observers = self._observers
        if not observers:
            return None
        me = get_ident()
        if self._owner == me:  # an observer logged: do not recurse into ourselves
            return None
        lock = self._lock
        lock.acquire()  # not `with`: this is the hot path of every observed step
        try:
            self._owner = me
            self._seq = seq = self._seq + 1
            event = _event(seq, _now(), self.run, self.machine, kind, path, fields)
            for observer in observers:
                try:
                    observer(event)
                except Exception:
                    self._failed(observer)
        finally:
            self._owner = None
            lock.release()
        return event

    def _failed(self, observer: Observer) -> None:
        """An observer could not take an event: said once per observer (with why), not per event,
        since one that fails once usually fails on every event that follows."""
        if any(o is observer for o in self._told):
            return
        self._told.append(observer)
        sys.stderr.write("fsm: an observer of machine %r failed (its next failures are not printed):\n%s"
                         % (self.machine, traceback.format_exc()))

    def begin_run(self) -> None:
        """Called by the root container as it starts: a new run id, then the structure if it
        changed since it was last sent (or an observer joined since)."""
        self.run = uuid.uuid4().hex[:12]
        if self._described_at != _generation:
            self._described_at = _generation
            self.emit("structure", self.root_path, {"root": self.structure()})

    def structure(self) -> dict:
        """Bind every state of the tree to this reporter and describe the tree (docs/events.md)."""
        label = self.root_path.rstrip("/").rsplit("/", 1)[-1] or "SM_ROOT"
        return _describe(self.root, label, self.root_path, self, {})


@functools.lru_cache(maxsize=1024)
def class_doc(cls: type) -> str | None:
    """The first paragraph of a class's own docstring, on one line, at most MAX_DOC characters: what a
    user's state does, for the page's details. None for fsm's own classes (the same text in every
    node would say nothing of the task) and a class without one (a docstring is never inherited)."""
    doc = cls.__dict__.get("__doc__")
    if not isinstance(doc, str) or cls.__module__.split(".")[0] == "fsm":
        return None
    first = " ".join(inspect.cleandoc(doc).split("\n\n")[0].split())
    if not first:
        return None
    return first if len(first) <= MAX_DOC else first[:MAX_DOC - 1] + "…"


def _describe(state: Any, label: str, path: str, rep: Reporter, remapping: dict) -> dict:
    state._reporter = rep
    state._path = path
    node = {"label": label, "path": path, "type": type(state).__name__,
            "container": is_container(state),
            "outcomes": sorted(map(str, state.get_registered_outcomes())),
            "input_keys": sorted(map(str, state.get_registered_input_keys())),
            "output_keys": sorted(map(str, state.get_registered_output_keys())),
            "remapping": {str(k): str(v) for k, v in (remapping or {}).items()}}
    doc = class_doc(type(state))
    if doc is not None:
        node["doc"] = doc
    if not node["container"]:
        return node
    if state.userdata._dirty is None:
        state.userdata._dirty = set()
    remappings = getattr(state, "_remappings", {})
    node["initial"] = [str(s) for s in state.get_initial_states()]
    node["children"] = [_describe(child, str(lbl), path + "/" + str(lbl), rep, remappings.get(lbl, {}))
                        for lbl, child in children(state).items()]
    node["transitions"] = [{"from": str(frm), "outcome": str(outcome), "to": None if to is None else str(to)}
                           for outcome, frm, to in state.get_internal_edges()]
    node.update(state._introspection_info())
    return node


def structure_changed() -> None:
    """A container was built or changed: the next run of every observed machine re-describes it."""
    global _generation
    _generation += 1


def attach(machine: Any, observer: Observer | None = None, name: str | None = None,
           path: str = DEFAULT_ROOT_PATH) -> Reporter:
    """Observe a top-level container; a second call adds an observer to the same reporter. ``name``
    must keep the name rule (fsm/observation/names.py: ValueError saying why); without one the
    machine is named after its root path."""
    rep = getattr(machine, "_reporter", None)
    if rep is None or rep.root is not machine:
        name = names.check(name) if name else names.valid(path.rsplit("/", 1)[-1] or "SM_ROOT")
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


def add_global_hook(hook: Hook) -> None:
    """``hook(container)`` runs whenever a top-level container starts executing, before its first event."""
    _hooks.append(hook)


def remove_global_hook(hook: Hook) -> None:
    if hook in _hooks:
        _hooks.remove(hook)


def on_top_level_start(container: Any) -> None:
    for hook in list(_hooks):
        try:
            hook(container)
        except Exception:
            sys.stderr.write("fsm: a global introspection hook failed:\n" + traceback.format_exc())


NOT_ENTERED = object()


def enter(rep: Reporter, path: str) -> Any:
    """Mark ``path`` as the innermost observed container running on this thread (for log events)."""
    prev = getattr(_tls, "ctx", None)
    _tls.ctx = (rep, path)
    return prev


def leave(prev: Any) -> None:
    if prev is not NOT_ENTERED:
        _tls.ctx = prev


def _on_log(level: str, msg: str) -> None:
    ctx = getattr(_tls, "ctx", None)
    if ctx is not None:
        ctx[0].emit("log", ctx[1], {"level": level, "msg": msg})


def _set_listening(rep: Reporter, on: bool) -> None:
    with _listening_lock:
        (_listening.add if on else _listening.discard)(rep)
        log.listener = _on_log if _listening else None


def userdata_fields(container: Any) -> dict:
    return encode_userdata(container.userdata._data)


def take_changes(userdata: Any) -> dict | None:
    """Encode the keys written since the last call, or None when nothing was written."""
    dirty = userdata._dirty
    if not dirty:
        return None
    userdata._dirty = set()
    data = userdata._data
    return encode_userdata({k: data[k] for k in dirty if k in data})


def carry_reported(error: BaseException, cause: BaseException) -> BaseException:
    """``error`` wraps ``cause``: when an ``error`` event already described ``cause``, none is sent for ``error``."""
    if getattr(cause, "_fsm_reported", False):
        error._fsm_reported = True  # type: ignore[attr-defined]
    return error


def error_fields(state_label: Any, exc: BaseException) -> dict:
    """Describe the root cause (the user's own exception), not SMACH's wrapper around it."""
    root = exc
    while root.__cause__ is not None:
        root = root.__cause__
    fields = {"state": None if state_label is None else str(state_label), "exc_type": type(root).__name__,
              "message": str(root), "traceback": "".join(traceback.format_exception(type(exc), exc, exc.__traceback__))}
    if root is not exc:
        fields["wrapped_as"] = type(exc).__name__
    return fields
