"""Helpers shared by the recording, replay, CLI and example tests."""

import contextlib
import os
import re
import resource
import runpy
import signal
import subprocess
import sys
import threading

import fsm
from fsm.logfiles.recorder import Recorder

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLES = os.path.join(ROOT, "examples")
FAST = {"FSMSCOPE_TIME_SCALE": "0.01"}


def load_example(name: str) -> dict:
    """The example's module globals (its ``__main__`` block does not run)."""
    return runpy.run_path(os.path.join(EXAMPLES, name + ".py"), run_name="example_" + name)


def record(sm, path, name: str = "m", **recorder_kwargs):
    """Run ``sm`` once with a Recorder on ``path``; returns (outcome, the events it was given)."""
    seen = []
    with Recorder(path, **recorder_kwargs) as recorder:
        fsm.attach(sm, recorder, name=name)
        fsm.attach(sm, seen.append)
        outcome = sm.execute()
    return outcome, seen


def cli(*args, cwd=None, env=None, timeout=60, memory=None):
    """``fsmscope ARGS`` in a real process; returns the CompletedProcess (text). ``memory``: a limit on
    its address space in bytes, so that a process that would take the machine's memory fails fast."""
    full_env = dict(os.environ, **(env or {}))
    full_env["PYTHONPATH"] = ROOT + os.pathsep + full_env.get("PYTHONPATH", "")
    if args and args[0] == "run" and "--exit" not in args:  # `run` keeps serving the dashboard unless --exit
        args = ("run", "--exit") + tuple(args[1:])

    def limited():
        resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    return subprocess.run([sys.executable, "-m", "fsmscope", *map(str, args)], cwd=cwd or ROOT, env=full_env,
                          capture_output=True, text=True, timeout=timeout, preexec_fn=memory and limited)


@contextlib.contextmanager
def replay_served(log, *args):
    """``fsmscope replay LOG --serve ARGS`` in a real process: yields (the address it printed, token
    included; the stderr lines before it); ended with Ctrl-C, as a user would, which exits 0."""
    proc = subprocess.Popen([sys.executable, "-m", "fsmscope", "replay", str(log), "--serve", *map(str, args)],
                            cwd=ROOT, stderr=subprocess.PIPE, text=True, start_new_session=True,
                            env={**os.environ, "PYTHONFAULTHANDLER": "1"})  # SIGABRT: every thread's stack
    later: list[str] = []
    drain = None
    try:
        said = []
        for line in proc.stderr:
            found = re.search(r"replaying \S+ at (http://\S+)", line)
            if found:
                break
            said.append(line)
        else:
            raise AssertionError("fsmscope replay --serve printed no address: %r" % said)
        # What it says after the address is read on, or a full pipe would stop it mid-line, Ctrl-C and all.
        drain = threading.Thread(target=later.extend, args=(proc.stderr,), daemon=True)
        drain.start()
        yield found.group(1), said
    finally:
        os.killpg(proc.pid, signal.SIGINT)
        try:
            code = proc.wait(20)
        except subprocess.TimeoutExpired:
            proc.send_signal(signal.SIGABRT)
            proc.wait(10)
            if drain is not None:
                drain.join(5)
            raise AssertionError("fsmscope replay --serve did not exit within 20 s of Ctrl-C; its threads:\n%s"
                                 % "".join(later)[-6000:]) from None
    assert code == 0, "fsmscope replay --serve exited %d on Ctrl-C; it said: %s" % (code, "".join(later)[-2000:])


def two_state_loop(n):
    """A machine that goes A -> B -> A ... until A has run ``n`` times, then ends 'done'."""
    from smach_support import Out, machine
    count = {"n": 0}

    def a(ud):
        count["n"] += 1
        return "stop" if count["n"] >= n else "go"
    return machine(["done"], [("A", Out(a, outcomes=["go", "stop"]), {"go": "B", "stop": "done"}),
                              ("B", Out("go", outcomes=["go"]), {"go": "A"})])
