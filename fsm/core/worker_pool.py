"""Long-lived threads for Concurrence children: no OS thread is started per child per execution."""

import threading
from collections import deque
from typing import Any, Callable


class WorkerPool:
    """A shared deque of jobs; whoever removes a job runs it.

    ``submit`` makes sure an idle worker exists for every queued job (spawning if needed), so a
    job never waits behind another and nested Concurrences cannot deadlock. ``take`` lets the
    submitter run a job itself when no worker has started it yet, which saves the thread
    hand-off for quick jobs. Jobs must catch their own exceptions.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._wake = threading.Condition(self._lock)
        self._jobs: deque = deque()
        self._idle = 0
        self._count = 0

    def submit(self, fn: Callable[..., Any], *args: Any) -> tuple:
        job = (fn, args)
        with self._lock:
            self._jobs.append(job)
            missing = len(self._jobs) - self._idle
            if missing > 0:
                for _ in range(missing):
                    self._count += 1
                    threading.Thread(target=self._loop, name="fsm-worker-%d" % self._count, daemon=True).start()
            else:
                self._wake.notify()
        return job

    def take(self, job: tuple) -> bool:
        """Remove ``job`` if no worker has started it; True means the caller must run it."""
        with self._lock:
            try:
                self._jobs.remove(job)
            except ValueError:
                return False
            return True

    def _loop(self) -> None:
        jobs = self._jobs
        with self._lock:
            while True:
                while not jobs:
                    self._idle += 1
                    self._wake.wait()
                    self._idle -= 1
                fn, args = jobs.popleft()
                self._lock.release()
                try:
                    fn(*args)
                finally:
                    del fn, args
                    self._lock.acquire()


pool = WorkerPool()
