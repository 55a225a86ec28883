"""smach_ros's introspection messages, and the SMACH lines of their nodes on /rosout, turned into
fsmscope events: one ``Follower`` per IntrospectionServer (smach_follower.py), fed one message at a
time, for a bag (``events``) as for a live stream (docs/interop.md says what each message tells,
and what nothing tells).

Order required: the messages of every topic merged by their stamps (``Message.t``: the header's
stamp). A bag, or a live stream, gives each topic's messages in the order they were received, and
the topics a few milliseconds apart: ``in_time_order`` merges them within a window.
"""

from __future__ import annotations

import heapq
import itertools
from collections import deque
from typing import Callable, Iterable, Iterator

from fsm.observation import names

from .bag_reader import Message
from .smach_follower import WAIT, Follower
from .smach_tree import UNKNOWN

__all__ = ["Follower", "UNKNOWN", "events", "in_time_order"]

WINDOW = 1.0  # seconds a message may come after one stamped later (rosbag writes each topic as received)
ORPHAN_LINES = 1000  # lines kept of a node whose server no message named yet


def in_time_order(messages: Iterable[Message], window: float = WINDOW) -> Iterator[Message]:
    """``messages`` in the order of their stamps, each let out once one ``window`` seconds later has come."""
    heap: list[tuple[float, int, Message]] = []
    for n, m in enumerate(messages):
        heapq.heappush(heap, (m.t, n, m))
        while heap[0][0] < m.t - window:
            yield heapq.heappop(heap)[2]
    while heap:
        yield heapq.heappop(heap)[2]


def events(messages: Iterable[Message], refused: Callable[[str], None] | None = None,
           untold: Callable[[str], None] | None = None) -> Iterator[dict]:
    """fsmscope's events of every introspection server in ``messages``, one machine per server named
    after it (a ROS name made a machine's name: ``robot/arm`` becomes ``robot_arm``,
    fsm/observation/names.py); each machine's events in order, the machines' merged by time. A line
    (kind "log") goes to the servers of its node (to every server when the node of none is known).
    A machine whose structure the schema refuses (too deep, a path too long, ...) has no events:
    ``refused`` hears why; ``untold`` hears of each machine whose last run's end is not known."""
    followers: dict[str, Follower] = {}
    nodes: dict[str | None, list[Follower]] = {}
    orphans: dict[str | None, deque] = {}
    taken: set[str] = set()
    out: list[tuple[float, int, dict]] = []
    counter = itertools.count()

    def emit(made: list[dict]) -> None:
        for ev in made:
            heapq.heappush(out, (ev["t"], next(counter), ev))

    for m in in_time_order(messages):
        if m.kind == "log":
            targets = nodes.get(m.node) or nodes.get(None, [])
            if m.node not in nodes:
                orphans.setdefault(m.node, deque(maxlen=ORPHAN_LINES)).append(m)
            for f in targets:
                emit(f.feed(m))
        else:
            f = followers.get(m.server)
            if f is None:
                f = followers[m.server] = Follower(m.server, names.unique(m.server, taken))
                taken.add(f.name)
                nodes.setdefault(m.node, []).append(f)
                lines = orphans.get(m.node, ()) if m.node is not None else itertools.chain(*orphans.values())
                for line in sorted((line for line in lines if line.t >= m.t - WAIT), key=lambda line: line.t):
                    emit(f.feed(line))  # its node's lines logged just before the server's first message
            emit(f.feed(m))
        while out and out[0][0] < m.t - WAIT - WINDOW:
            yield heapq.heappop(out)[2]
    for f in followers.values():
        emit(f.end())
        if f.refused is not None and refused is not None:
            refused("machine %s, whose structure does not fit the schema: %s" % (f.name, f.refused))
        elif f.finished is False and untold is not None:
            untold("machine %s: the end of its last run is not in the bag (its node's SMACH lines on /rosout "
                   "tell it)" % f.name)
    while out:
        yield heapq.heappop(out)[2]
