"""Debian's Chromium driven by Playwright, and the demo as a real process: shared by the browser
tests and docs/screenshot.py (the README's screenshot is made with the same tooling)."""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

CHROMIUM = "/usr/bin/chromium"
# No downloads and no GPU here: software WebGL (for viser's scene) and no background networking.
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--enable-unsafe-swiftshader"]
ROOT = Path(__file__).resolve().parents[1]
FSMSCOPE = [sys.executable, "-m", "server.cli"]


def launch_chromium(playwright):
    """A headless Chromium from the Debian package, with a fresh temporary profile."""
    return playwright.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class DemoProcess:
    """``fsmscope demo`` in its own process group; ``url`` is the dashboard address it printed."""

    def __init__(self, record: Path, *extra: str, token: str = "demo-test-token") -> None:
        self.token = token
        self.record = record
        self.port = free_port()
        self.proc = subprocess.Popen(
            FSMSCOPE + ["demo", "--port", str(self.port), "--token", token, "--record", str(record), *extra],
            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True)
        self.url = self._wait_for_url()

    def _wait_for_url(self, timeout: float = 60.0) -> str:
        deadline = time.monotonic() + timeout
        lines = []
        while time.monotonic() < deadline:
            line = self.proc.stdout.readline()
            if not line:
                break
            lines.append(line)
            found = re.search(r"open (http://\S+)", line)
            if found:
                return found.group(1)
        self.stop()
        raise RuntimeError("fsmscope demo printed no URL:\n" + "".join(lines))

    def stop(self, timeout: float = 20.0) -> int:
        """SIGINT, as Ctrl-C would; returns the exit code."""
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGINT)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
        if self.proc.stdout is not None:
            self.rest = self.proc.stdout.read()
            self.proc.stdout.close()
        return self.proc.returncode
