"""``fsmscope run``: run a user's SMACH-style script as ``__main__`` and record every machine it runs.

The script does not know: a global introspection hook attaches a Recorder to each
top-level machine the first time it starts (an fsm machine through ``fsm.add_global_hook``, one of
the original smach through ``original_machines``), naming it after the script (``foo_bar``,
then ``foo_bar-2`` for a second machine: fsm/observation/names.py). Whoever serves a dashboard registers
``on_machine`` callbacks to attach its own observers to the same machines (they run in
the machine's thread, before its first event).

With ``keep_open`` the log stays open after the script ends (``fsmscope run`` keeps serving the
dashboard, where POST .../start re-runs a machine: those runs are recorded too) until
``close()``, which writes what is left, fsyncs and says what was recorded.

A script that does ``import smach`` runs as it is: on the original smach where it is installed, and
otherwise on fsm with ROS-free counterparts of smach, smach_ros and rospy (fsmscope/counterparts/,
installed for the run only by ``ScriptImports``; docs/guide.md, "Unchanged SMACH scripts").

A log is never written onto unless asked (``append``): a command refuses a file that exists
(``open_recorder``), as ``import`` and ``export`` do.
"""

from __future__ import annotations

import itertools
import os
import runpy
import signal
import sys
import threading
import time
import traceback
from dataclasses import dataclass, field
from typing import Any, Callable

import fsm
from fsm.observation import names
from fsm.observation.introspection import reporter_of
from fsm.logfiles.recorder import Recorder
from fsmscope.counterparts.finder import ScriptImports

from .original_machines import OriginalMachines

MachineCallback = Callable[[str, Any], None]
EXIT_NOT_RECORDED = 1  # the script ended well, but its log could not be written whole
EXIT_CANNOT_RECORD = 2  # the log was refused (it exists) or cannot be opened: nothing ran


def open_recorder(path: str | None, append: bool, command: str, script: str) -> tuple[str, Recorder | None]:
    """The log's path and its recorder: ``path``, a new file unless ``append``; None for it, ``runs/
    <script>-<time>.jsonl`` (or ``-2``, ``-3``... when a run of the same second has it), opened
    exclusively, so two processes started in the same second never write one file. The recorder is
    None, said on stderr as ``fsmscope COMMAND``, when the file exists (and ``append`` is not given)
    or cannot be opened."""
    try:
        if path is not None:
            return path, Recorder(path, new=not append)
        stem = os.path.join("runs", "%s-%s" % (os.path.splitext(os.path.basename(script))[0],
                                               time.strftime("%Y%m%d-%H%M%S")))
        for n in itertools.count(1):
            path = stem + ("-%d" % n if n > 1 else "") + ".jsonl"
            try:
                return path, Recorder(path, new=True)
            except FileExistsError:  # another run of the same second took it
                continue
    except FileExistsError:
        sys.stderr.write("fsmscope %s: %s exists already: --append adds to it, or record to another file\n"
                         % (command, path))
    except OSError as exc:
        sys.stderr.write("fsmscope %s: cannot record to %s: %s\n" % (command, path, exc.strerror or exc))
    return str(path), None


@dataclass
class Machine:
    name: str
    container: Any


@dataclass
class Runner:
    """Runs one script with recording; ``run()`` returns its exit code (as ``python script.py`` would)."""

    script: str
    args: list[str] = field(default_factory=list)
    record: str | None = None  # path of the log; None: runs/<script>-<timestamp>.jsonl
    append: bool = False  # add to the log when it exists (else it is refused)
    on_machine: list[MachineCallback] = field(default_factory=list)
    machines: list[Machine] = field(default_factory=list)
    recorder: Recorder | None = None
    keep_open: bool = False  # leave the log open when the script ends, until close()
    signalled: int | None = None  # the signal (SIGINT, SIGTERM) that ended the script, if one did

    def __post_init__(self) -> None:
        self.stem = os.path.splitext(os.path.basename(self.script))[0]
        self.record_path = self.record or ""  # the default's name is found when the log is opened (prepare)
        self._lock = threading.Lock()
        self._restore_sigterm: Callable[[], None] = lambda: None
        self._originals: list[OriginalMachines] = []

    def _hook(self, container: Any) -> None:
        with self._lock:
            if any(m.container is container for m in self.machines):
                return
            rep = reporter_of(container)
            if rep is not None:  # the script attached it itself: keep the name it chose
                name = rep.machine
            else:
                name = names.unique(self.stem, {m.name for m in self.machines})
            machine = Machine(name, container)
            self.machines.append(machine)
        fsm.attach(container, self.recorder, name=name)
        for callback in list(self.on_machine):
            try:
                callback(name, container)
            except Exception:
                sys.stderr.write("fsmscope: an on_machine callback failed:\n" + traceback.format_exc())

    def prepare(self) -> int | None:
        """Find the script and open the log, before anything else starts (a dashboard, a robot);
        the exit code when either cannot be (said on stderr), else None."""
        if not os.path.isfile(os.path.abspath(self.script)):
            sys.stderr.write("fsmscope run: %s: no such file\n" % self.script)
            return 2
        self.record_path, self.recorder = open_recorder(self.record, self.append, "run", self.script)
        return EXIT_CANNOT_RECORD if self.recorder is None else None

    def run(self) -> int:
        """Run the script (``prepare`` first, unless done); its exit code."""
        if self.recorder is None:
            refused = self.prepare()
            if refused is not None:
                return refused
        sys.stderr.write("fsmscope: recording to %s\n" % self.record_path)
        script = os.path.abspath(self.script)
        saved_argv, saved_path0 = sys.argv, sys.path[0] if sys.path else None
        sys.argv = [self.script] + list(self.args)
        if sys.path:
            sys.path[0] = os.path.dirname(script)
        else:
            sys.path.insert(0, os.path.dirname(script))
        self._restore_sigterm = _sigterm_as_exit(self._note_signal)
        fsm.add_global_hook(self._hook)
        imports = ScriptImports(self._watch_original, lambda line: sys.stderr.write("fsmscope: %s\n" % line))
        imports.install()
        code = 0
        try:
            runpy.run_path(script, run_name="__main__")
        except SystemExit as exc:
            code = _exit_code(exc.code)
        except KeyboardInterrupt:
            self._note_signal(signal.SIGINT)
            code = 130
        except BaseException:
            traceback.print_exc()
            code = 1
        finally:
            fsm.remove_global_hook(self._hook)
            imports.uninstall()
            for originals in self._originals:
                originals.stop()
            self._originals.clear()
            sys.argv = saved_argv
            if saved_path0 is not None and sys.path:
                sys.path[0] = saved_path0
            if not self.keep_open:
                self.close()
        return code if self.keep_open else self.exit_code(code)

    def _watch_original(self, smach: Any) -> None:
        self._originals.append(OriginalMachines(smach, self._hook))

    def _note_signal(self, signum: int) -> None:
        self.signalled = signum

    def close(self) -> None:
        """Close the log (write, fsync) and say what it holds (a failed write the recorder said
        already); idempotent."""
        recorder = self.recorder
        if recorder is None or recorder.closed:
            return
        recorder.close()
        self._restore_sigterm()  # SIGTERM closed the log through SystemExit until now
        if recorder.failure is None and not self.machines:
            sys.stderr.write("fsmscope: no machine ran: no log written\n")
        elif recorder.failure is None:
            names = ", ".join(m.name for m in self.machines)
            sys.stderr.write("fsmscope: recorded %d events (%s) to %s\n" % (recorder.events, names, self.record_path))

    def exit_code(self, code: int) -> int:
        """The command's exit code for a script that exited ``code``: EXIT_NOT_RECORDED instead of 0
        when its log could not be written whole (a full disk)."""
        failed = self.recorder is not None and self.recorder.failure is not None
        return EXIT_NOT_RECORDED if code == 0 and failed else code


def _exit_code(code: Any) -> int:
    if code is None:
        return 0
    if isinstance(code, int):
        return code
    sys.stderr.write("%s\n" % code)
    return 1


def _sigterm_as_exit(noted: Callable[[int], None]) -> Callable[[], None]:
    """Turn SIGTERM into SystemExit (so the log is closed) unless the script handles it itself;
    ``noted`` hears of it first, whatever the script then makes of the SystemExit."""
    if threading.current_thread() is not threading.main_thread() or signal.getsignal(signal.SIGTERM) != signal.SIG_DFL:
        return lambda: None

    def on_sigterm(signum: int, frame: Any) -> None:
        noted(signum)
        raise SystemExit(128 + signum)

    signal.signal(signal.SIGTERM, on_sigterm)

    def restore() -> None:
        if signal.getsignal(signal.SIGTERM) is on_sigterm:
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
    return restore

