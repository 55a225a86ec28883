"""Graphviz ``dot`` kept running: a few ``dot -Tsvg`` processes, each fed graph after graph.

A process per layout spent ~10 ms starting dot and loading its fonts, and a drawing asks for one
layout per depth of its open containers (a parent is laid out around its children's finished
drawings): at every semantic zoom re-layout that was 40 ms before anything was laid out. A kept
process writes each drawing as soon as it has read its graph. One that fails (dot exits on an
error) or outlasts the timeout is killed and replaced; one is also replaced after MAX_LAYOUTS.
"""

from __future__ import annotations

import os
import selectors
import shutil
import subprocess
import tempfile
import threading
import time

MAX_LAYOUTS = 2000  # graphs one process lays out before it is replaced (Graphviz is not made to live long)
_END = b"</svg>\n"  # the end of one drawing: text in it is escaped, so only the end has it


class DotError(Exception):
    """Graphviz is missing, failed, or took too long."""


class _Process:
    """One running ``dot -Tsvg``; used by one thread at a time."""

    def __init__(self, exe: str) -> None:
        self.errors = tempfile.TemporaryFile()  # a file, not a pipe: warnings never fill a buffer and block dot
        self.proc = subprocess.Popen([exe, "-Tsvg"], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=self.errors)
        os.set_blocking(self.proc.stdin.fileno(), False)
        os.set_blocking(self.proc.stdout.fileno(), False)
        self.layouts = 0

    def layout(self, graphs: list[bytes], timeout: float) -> list[bytes]:
        """The SVG of each graph, in order; writes and reads at once (dot answers while it reads)."""
        todo = memoryview(b"".join(g + b"\n" for g in graphs))
        out = bytearray()
        deadline = time.monotonic() + timeout
        with selectors.DefaultSelector() as sel:
            sel.register(self.proc.stdout, selectors.EVENT_READ)
            if todo:
                sel.register(self.proc.stdin, selectors.EVENT_WRITE)
            while out.count(_END) < len(graphs):
                left = deadline - time.monotonic()
                if left <= 0:
                    raise DotError("dot took longer than %.0f s" % timeout)
                for key, _ in sel.select(left):
                    if key.fileobj is self.proc.stdin:
                        try:
                            todo = todo[os.write(self.proc.stdin.fileno(), todo):]
                        except BrokenPipeError:
                            raise DotError(self._failure()) from None
                        if not todo:
                            sel.unregister(self.proc.stdin)
                    else:
                        chunk = os.read(self.proc.stdout.fileno(), 1 << 16)
                        if not chunk:
                            raise DotError(self._failure())
                        out += chunk
        self.layouts += len(graphs)
        docs = bytes(out).split(b"<?xml")[1:]
        if len(docs) != len(graphs):
            raise DotError("dot returned %d drawings for %d graphs" % (len(docs), len(graphs)))
        return [b"<?xml" + doc for doc in docs]

    def _failure(self) -> str:
        self.proc.wait(5)
        self.errors.seek(0)
        return "dot failed: %s" % self.errors.read(500).decode(errors="replace")

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()
        for f in (self.proc.stdin, self.proc.stdout, self.errors):
            f.close()


class DotPool:
    """At most ``size`` dot processes, lent to one caller at a time."""

    def __init__(self, size: int) -> None:
        self.size = size
        self._idle: list[_Process] = []
        self._running = 0
        self._free = threading.Condition()

    def layout(self, graphs: list[bytes], timeout: float) -> list[bytes]:
        """Lay ``graphs`` (DOT text) out with one process; their SVG drawings, in order."""
        process = self._borrow()
        try:
            docs = process.layout(graphs, timeout)
        except BaseException:
            self._give_back(process, broken=True)
            raise
        self._give_back(process, broken=process.layouts >= MAX_LAYOUTS)
        return docs

    def _borrow(self) -> _Process:
        with self._free:
            while not self._idle and self._running >= self.size:
                self._free.wait()
            if self._idle:
                return self._idle.pop()
            exe = shutil.which("dot")
            if exe is None:
                raise DotError("Graphviz 'dot' is not installed")
            self._running += 1
        try:
            return _Process(exe)
        except OSError as exc:
            self._give_back(None, broken=True)
            raise DotError("could not start dot: %s" % exc) from exc

    def _give_back(self, process: _Process | None, broken: bool) -> None:
        if broken and process is not None:
            process.close()
        with self._free:
            if broken:
                self._running -= 1
            else:
                self._idle.append(process)
            self._free.notify()

    def close(self) -> None:
        """Stop the idle processes (those lent out stop when given back broken, or with the program)."""
        with self._free:
            idle, self._idle = self._idle, []
            self._running -= len(idle)
        for process in idle:
            process.close()
