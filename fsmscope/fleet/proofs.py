"""Proofs of a robot's token on the fleet's network. Any Zenoh session that reaches the network can
put on a robot's keys, answer its queries and receive its dashboards' queries, so nothing a robot or
a dashboard sends carries the token itself: each message carries an HMAC-SHA256 of what it says,
keyed with the token, which only a holder of the token can make (stdlib ``hmac``):

- a robot's batch of events, over its key, the robot's process (its session id) and the batch;
- a robot's answer to a query, over the query's key, the query's nonce and the answer: a recorded
  answer does not answer another query, and a forged one is refused;
- a dashboard's control, over the control's key and its request, which names the robot's process
  it is for and the dashboard's session with a counter: the robot refuses a counter it has taken
  (``ReplayWindow``), and a control recorded for one process means nothing to the next;
- a dashboard's heartbeat to a robot whose machine it leases, with a counter the robot only takes
  rising: a recorded beat cannot keep a dead dashboard's lease alive.

Each purpose is a different message to the HMAC (``PURPOSES``): a proof made for one is never taken
for another. Imports only the standard library.
"""

from __future__ import annotations

import hashlib
import hmac
import sys

SIZE = 32  # bytes of a proof (SHA-256)
PURPOSES = (b"events", b"answer", b"control", b"beat")
WINDOW = 1024  # counters below a dashboard's highest that may still come (its controls race each other)


def sign(token: str, purpose: bytes, key: str, *parts: bytes) -> bytes:
    """The proof of ``parts`` sent on ``key`` for ``purpose``; each part is framed by its length, so
    no two different messages are the same bytes to the HMAC."""
    assert purpose in PURPOSES
    mac = hmac.new(token.encode(), purpose, hashlib.sha256)
    for part in (key.encode(), *parts):
        mac.update(len(part).to_bytes(8, "big"))
        mac.update(part)
    return mac.digest()


def proven(token: str | None, proof: bytes | None, purpose: bytes, key: str, *parts: bytes) -> bool:
    """Whether ``proof`` is the proof of ``parts`` by ``token`` (never, with no token)."""
    return bool(token) and proof is not None and len(proof) == SIZE and \
        hmac.compare_digest(proof, sign(token, purpose, key, *parts))


class ReplayWindow:
    """The counters taken from each sender (a dashboard's session): a counter is taken once, and one
    more than ``WINDOW`` below the sender's highest is refused (RFC 4303's anti-replay window).
    Only senders that proved the token are remembered, the ``senders`` newest of them."""

    def __init__(self, senders: int = 256) -> None:
        self.senders = senders
        self._taken: dict[str, tuple[int, set[int]]] = {}  # sender: (highest, counters taken within the window)

    def take(self, sender: str, counter: int) -> bool:
        """True the first time ``counter`` comes from ``sender`` (within the window), False after."""
        highest, taken = self._taken.pop(sender, (0, set()))
        fresh = counter > highest - WINDOW and counter not in taken
        if fresh:
            taken.add(counter)
            if counter > highest:
                highest = counter
                taken = {seen for seen in taken if seen > highest - WINDOW}
        self._taken[sender] = (highest, taken)  # the newest sender last: the oldest go first
        while len(self._taken) > self.senders:
            del self._taken[next(iter(self._taken))]
        return fresh


class Tally:
    """Refusals counted, and said on stderr the 1st, 2nd, 4th, 8th... time: a stranger's flood of
    forged messages costs a line per doubling, not a line each."""

    def __init__(self, who: str) -> None:
        self.who = who
        self.count = 0

    def refused(self, what: str) -> None:
        self.count += 1
        if self.count & (self.count - 1) == 0:
            print("%s: refused %s; %d refused so far" % (self.who, what, self.count), file=sys.stderr, flush=True)
