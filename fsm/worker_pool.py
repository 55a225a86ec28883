"""Long-lived threads for Concurrence children: no OS thread is started per child per execution."""

import threading
from queue import SimpleQueue
from typing import Any, Callable


class _Worker:
    __slots__ = ("jobs",)

    def __init__(self, pool: "WorkerPool", index: int) -> None:
        self.jobs: SimpleQueue = SimpleQueue()
        threading.Thread(target=self._loop, args=(pool,), name="fsm-worker-%d" % index, daemon=True).start()

    def _loop(self, pool: "WorkerPool") -> None:
        jobs = self.jobs
        idle = pool._idle
        while True:
            fn, args = jobs.get()
            try:
                fn(*args)
            finally:
                del fn, args
                idle.append(self)


class WorkerPool:
    """Hands each job to an idle worker, or to a new one: never waits for a free worker, so nested
    Concurrences cannot deadlock. Jobs must catch their own exceptions."""

    def __init__(self) -> None:
        self._idle: list[_Worker] = []
        self._count = 0
        self._lock = threading.Lock()

    def submit(self, fn: Callable[..., Any], *args: Any) -> None:
        try:
            worker = self._idle.pop()
        except IndexError:
            with self._lock:
                self._count += 1
                worker = _Worker(self, self._count)
        worker.jobs.put((fn, args))

    @property
    def size(self) -> int:
        return self._count


pool = WorkerPool()
