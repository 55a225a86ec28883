"""A dashboard's joins: the machines whose state it must ask (seen alive, back, or from a new process).
One thread sends their state queries without waiting for them, up to ``MAX_JOINS`` on their way at
once (more wait for their turn), and hands each answer that proves the robot's token to ``join``,
which asks the history and takes the machine. A machine that answers slowly, or a stranger's token
that nobody answers for, costs the others nothing: sixty such tokens held a new robot off for more
than 45 s when the joins were asked one at a time."""

from __future__ import annotations

import collections
import queue
import threading
from typing import Callable

import zenoh

from . import keys
from .query import send

MAX_JOINS = 256  # machines whose state query is on its way at once; more wait for their turn
QUERY_TIMEOUT = 5.0  # seconds a state or history query waits for the robot's answer


class Joins:
    """``ask(key)`` from any thread; ``join((key, answer))`` and then ``settled()`` are called in the
    joins' thread, for each state answer that came; ``token_of(robot)`` proves the answers."""

    def __init__(self, session: zenoh.Session, token_of: Callable[[str], str | None],
                 join: Callable[[tuple[str, bytes]], None], settled: Callable[[], None]) -> None:
        self.session = session
        self.token_of = token_of
        self.join = join
        self.settled = settled
        # Machine keys to join, and state answers (key, answer); None: stop.
        self._queue: queue.SimpleQueue[str | tuple[str, bytes | None] | None] = queue.SimpleQueue()
        self._joining: set[str] = set()  # keys whose state query is on its way (this thread's only)
        self._waiting: collections.deque[str] = collections.deque()  # keys past MAX_JOINS, in turn
        self._cancel = zenoh.CancellationToken()  # the state queries on their way, at close
        threading.Thread(target=self._run, name="fsmscope-fleet-joins", daemon=True).start()

    def ask(self, key: str) -> None:
        """Join the machine of ``key`` (its liveliness key), unless its join is on its way."""
        self._queue.put(key)

    def close(self) -> None:
        """Stop, and end the queries on their way (before the session closes)."""
        self._queue.put(None)
        self._cancel.cancel()

    def _run(self) -> None:
        try:
            while (item := self._queue.get()) is not None:
                if type(item) is str:
                    self._send(item)
                    continue
                key, answer = item
                self._joining.discard(key)
                while self._waiting and len(self._joining) < MAX_JOINS:
                    self._send(self._waiting.popleft())
                if answer is not None:
                    self.join((key, answer))
                    self.settled()
        except zenoh.ZError:  # the session closed
            pass

    def _send(self, key: str) -> None:
        """The machine's state query, unless one is on its way (or waits)."""
        if key in self._joining or key in self._waiting:
            return
        if len(self._joining) >= MAX_JOINS:
            self._waiting.append(key)
            return
        self._joining.add(key)
        robot, machine = keys.split(key)
        send(self.session, keys.state_key(robot, machine), self.token_of(robot), QUERY_TIMEOUT,
             lambda answer: self._queue.put((key, answer)), cancel=self._cancel)
