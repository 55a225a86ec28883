"""``fsmscope demo`` as a real process, the way a user starts it: for the demo's tests, the CPU
benchmark and the README's screenshot."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
from pathlib import Path

from fsmscope.server.testing.polling import wait_for

FSMSCOPE = [sys.executable, "-m", "fsmscope"]


def free_port() -> int:
    """A TCP port of 127.0.0.1 that nothing listens on right now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def interrupt(proc: subprocess.Popen, timeout: float) -> int:
    """SIGINT to the process group ``proc`` leads (started with ``start_new_session``), as Ctrl-C
    would; SIGKILL if it has not exited within ``timeout`` s. Returns the exit code."""
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGINT)
        try:
            proc.wait(timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    return proc.returncode


def free_endpoint() -> str:
    """A Zenoh endpoint, ``tcp/127.0.0.1:PORT``, on a port free right now (the fleet's tests and benches)."""
    return "tcp/127.0.0.1:%d" % free_port()


class DemoProcess:
    """``fsmscope demo`` in its own process group; ``url`` is the dashboard address it printed."""

    def __init__(self, record: Path, *extra: str, token: str = "demo-test-token") -> None:
        self.token = token
        self.record = record
        self.port = free_port()
        self.proc = subprocess.Popen(
            FSMSCOPE + ["demo", "--port", str(self.port), "--token", token, "--record", str(record), *extra],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True)
        self.url = self._wait_for_url()

    def _wait_for_url(self, timeout: float = 60.0) -> str:
        lines: list[str] = []

        def printed_url() -> str | None:
            line = self.proc.stdout.readline()
            if not line:
                raise EOFError("fsmscope demo closed its output")
            lines.append(line)
            found = re.search(r"open (http://\S+)", line)
            return found.group(1) if found else None

        try:
            return wait_for(printed_url, timeout, interval=0, what="fsmscope demo to print its URL")
        except (EOFError, TimeoutError) as gave_up:
            self.stop()
            raise RuntimeError("fsmscope demo printed no URL:\n" + "".join(lines)) from gave_up

    def stop(self, timeout: float = 20.0) -> int:
        """SIGINT, as Ctrl-C would; returns the exit code."""
        interrupt(self.proc, timeout)
        if self.proc.stdout is not None:
            self.rest = self.proc.stdout.read()
            self.proc.stdout.close()
        return self.proc.returncode
