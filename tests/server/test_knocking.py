"""Knocking at a real `fsmscope serve`: refused websocket handshakes (a wrong token, a foreign Origin,
a foreign Host) and malformed requests do not fill its terminal (fsmscope/server/middleware.py): a refused
handshake is said by no line, a malformed request by at most one a minute."""

from __future__ import annotations

import os
import queue
import re
import signal
import socket
import subprocess
import sys
import threading
import time

from recording_support import ROOT

KNOCKS = 300


def handshake(port: int, path: str, host: str, origin: str | None = None) -> str:
    """The status line that the server answers a raw websocket handshake with."""
    head = ("GET %s HTTP/1.1\r\nHost: %s\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
            "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n" % (path, host))
    if origin is not None:
        head += "Origin: %s\r\n" % origin
    return sent(port, (head + "\r\n").encode())


def sent(port: int, data: bytes) -> str:
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall(data)
        return s.makefile("rb").readline().decode().strip()


def serving() -> tuple[subprocess.Popen, int, queue.Queue]:
    """`fsmscope serve` in a real process, its port, and the lines of its stderr after its address."""
    proc = subprocess.Popen([sys.executable, "-m", "fsmscope", "serve", "--port", "0"], cwd=ROOT, text=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True,
                            env=dict(os.environ, PYTHONPATH=ROOT))
    for line in proc.stderr:
        found = re.search(r"serving the dashboard at http://127\.0\.0\.1:(\d+)/", line)
        if found:
            break
    else:
        raise AssertionError("fsmscope serve said no address")
    lines: queue.Queue = queue.Queue()
    threading.Thread(target=lambda: [lines.put(line) for line in proc.stderr] and None, daemon=True).start()
    return proc, int(found.group(1)), lines


def test_many_refused_handshakes_and_malformed_requests_leave_at_most_one_line():
    proc, port, lines = serving()
    here = "127.0.0.1:%d" % port
    try:
        for _ in range(KNOCKS):
            assert handshake(port, "/api/machines/m/stream?token=wrong", here).startswith("HTTP/1.1 401")
            assert handshake(port, "/api/overview/stream", here, origin="https://evil.example").startswith("HTTP/1.1 403")
            assert handshake(port, "/api/ingest", "evil.example:%d" % port).startswith("HTTP/1.1 400")
            assert sent(port, b"\x16\x03\x01 not http\r\n\r\n").startswith("HTTP/1.1 400")
        time.sleep(0.5)  # what the server said about the last ones reaches its stderr
    finally:
        os.killpg(proc.pid, signal.SIGINT)
        proc.wait(20)
    said = [line for line in lines.queue if not line.startswith("fsmscope: other processes publish with")]
    assert len(said) == 1 and "Invalid HTTP request received. (said at most once a minute)" in said[0], said
