"""What the parity tests share: a Side (one implementation, its log lines), what a call gave, and
the normalisation of what legitimately differs between the original SMACH and fsm."""

import re
import threading
from types import SimpleNamespace
from typing import Any, Callable

import fsm

LEVELS = ("info", "warn", "debug", "error")


class Side:
    """One implementation as a script sees it: ``sm`` is what the script calls ``smach``.

    Every log line is kept in order as ``(level, message)``; ``when_logged(text)`` gives an event set
    once a line containing ``text`` was logged (children of a Concurrence wait on each other with it,
    so that their lines come in one order on both sides)."""

    def __init__(self, sm: Any) -> None:
        self.sm = sm
        self.logs: list[tuple[str, str]] = []
        self.thread_errors: list[tuple[str, str]] = []  # exceptions that ended a thread of its own
        self._waits: list[tuple[str, threading.Event]] = []
        self._lock = threading.Lock()
        sm.set_loggers(*[self._printer(level) for level in LEVELS])

    def _printer(self, level: str) -> Callable[[object], None]:
        def printer(message: object) -> None:
            with self._lock:
                self.logs.append((level, str(message)))
                for text, event in self._waits:
                    if text in str(message):
                        event.set()
        return printer

    def when_logged(self, text: str) -> threading.Event:
        event = threading.Event()
        with self._lock:
            self._waits.append((text, event))
            if any(text in message for _, message in self.logs):
                event.set()
        return event


def outcome_of(fn: Callable[[], Any]) -> tuple:
    """What calling ``fn`` gave: ``("returned", value)`` or ``("raised", type name, message)``."""
    try:
        return ("returned", fn())
    except Exception as exc:
        return ("raised", type(exc).__name__, str(exc))


_ADDRESS = re.compile(r" at 0x[0-9a-fA-F]+")
_MODULE = re.compile(r"\b(?:smach|fsm(?:\.core)?)\.(state|user_data|container|state_machine|concurrence|iterator|"
                     r"sequence|util|exceptions)\.")
_FRAMES = re.compile(r"^(?:  .*\n)+", re.MULTILINE)


def normalised(value: Any) -> Any:
    """``value`` with what legitimately differs between the two made equal: object addresses, the
    module a core class lives in (``smach.state`` against ``fsm.core.state``) and the frames of a
    traceback (each run of indented lines becomes one; the rest, the exception lines, is kept)."""
    if isinstance(value, str):
        value = _ADDRESS.sub(" at 0x…", value)
        value = _MODULE.sub(r"smach.\1.", value)
        return _FRAMES.sub("  …\n", value)
    if isinstance(value, (list, tuple)):
        return type(value)(normalised(v) for v in value)
    if isinstance(value, dict):
        return {normalised(k): normalised(v) for k, v in value.items()}
    return value


class Parity:
    """Runs one scenario on both implementations; see ``same``."""

    def __init__(self, original: Any) -> None:
        self.original = original

    def run(self, scenario: Callable[[Side], Any]) -> tuple[Any, Any]:
        """``scenario(side)`` on the original, then on fsm: (original's, fsm's), each the scenario's
        result, the side's log lines and the exceptions that ended a thread, normalised."""
        results = []
        for side in (Side(self.original), Side(fsm)):
            hook = threading.excepthook
            threading.excepthook = lambda args: side.thread_errors.append((args.exc_type.__name__, str(args.exc_value)))
            try:
                result = scenario(side)
            finally:
                threading.excepthook = hook
            results.append(normalised({"result": result, "logs": side.logs, "thread_errors": side.thread_errors}))
        return results[0], results[1]

    def same(self, scenario: Callable[[Side], Any]) -> Any:
        """Asserts that both implementations give the same result, log the same lines and end no
        thread differently; returns fsm's."""
        theirs, ours = self.run(scenario)
        assert ours["result"] == theirs["result"]
        assert ours["logs"] == theirs["logs"]
        assert ours["thread_errors"] == theirs["thread_errors"]
        return ours


def kit(sm: Any) -> Any:
    """Small states and builders made of one implementation's classes (``sm``), alike on both sides."""

    class Out(sm.State):
        """Returns ``result``, or ``result(ud)`` when it is callable (its outcomes then default to ['done'])."""

        def __init__(self, result: Any = "done", outcomes: Any = None, input_keys: list = [],
                     output_keys: list = [], io_keys: list = []) -> None:
            if outcomes is None:
                outcomes = ["done"] if callable(result) else [result]
            sm.State.__init__(self, outcomes, input_keys, output_keys, io_keys)
            self.result = result
            self.saw_preempt: list[bool] = []

        def execute(self, ud: Any) -> Any:
            self.saw_preempt.append(self.preempt_requested())
            return self.result(ud) if callable(self.result) else self.result

    class WaitForPreempt(sm.State):
        """Blocks until preempted (``started`` is set once it runs), services the preempt if told
        to, and returns ``result``; 'timeout' after 5 s without a preempt."""

        def __init__(self, outcomes: Any = ("preempted",), service: bool = True, result: str = "preempted") -> None:
            sm.State.__init__(self, list(outcomes))
            self.started = threading.Event()
            self.preempted = threading.Event()
            self.service = service
            self.result = result

        def request_preempt(self) -> None:
            sm.State.request_preempt(self)
            self.preempted.set()

        def execute(self, ud: Any) -> str:
            self.started.set()
            if not self.preempted.wait(5):
                return "timeout"
            self.preempted.clear()
            if self.service:
                self.service_preempt()
            return self.result

    def machine(outcomes: list, children: list, **kwargs: Any) -> Any:
        """A StateMachine of ``(label, state, transitions[, remapping])`` tuples."""
        built = sm.StateMachine(outcomes=outcomes, **kwargs)
        with built:
            for child in children:
                sm.StateMachine.add(*child)
        return built

    def concurrence(outcomes: list, default_outcome: str, children: list, **kwargs: Any) -> Any:
        """A Concurrence of ``(label, state[, remapping])`` tuples."""
        built = sm.Concurrence(outcomes=outcomes, default_outcome=default_outcome, **kwargs)
        with built:
            for child in children:
                sm.Concurrence.add(*child)
        return built

    return SimpleNamespace(Out=Out, WaitForPreempt=WaitForPreempt, machine=machine, concurrence=concurrence)
