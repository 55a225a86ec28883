"""Asking a robot: a Zenoh query's first answer. A query that no queryable matched ends at once with
no reply, and one sent on a link that is being dropped ends when it is dropped; both happen in the
moment a robot is back on the network (its liveliness token may reach the dashboard before its
queryables' declarations, and the dead link before the cut is dropped only at its lease's end).
Such a query ends before its timeout without a reply and is asked again, until ``timeout``. A
query that waited its whole time for a reply is not asked again: it may have reached the robot."""

from __future__ import annotations

import time

import zenoh

RETRY_EVERY = 0.1  # seconds between two asks that reached nobody


def first_reply(session: zenoh.Session, selector: str, timeout: float, payload: bytes | None = None) -> bytes | None:
    """The payload of the first good reply to ``selector``; None when none came within ``timeout``."""
    deadline = time.monotonic() + timeout
    while True:
        left = deadline - time.monotonic()
        started = time.monotonic()
        for reply in session.get(selector, payload=payload, timeout=max(left, 0.01)):
            if reply.ok is not None:
                return reply.ok.payload.to_bytes()
        if time.monotonic() - started >= left * 0.9 or deadline - time.monotonic() < RETRY_EVERY:
            return None  # it waited for an answer that did not come: the query reached something
        time.sleep(RETRY_EVERY)
