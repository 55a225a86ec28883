"""Asking a robot: a Zenoh query's first answer that proves the robot's token. A query that no
queryable matched ends at once with no reply, and one sent on a link that is being dropped ends when
it is dropped; both happen in the moment a robot is back on the network (its liveliness token may
reach the dashboard before its queryables' declarations, and the dead link before the cut is dropped
only at its lease's end). Such a query ends before its timeout without a reply and is asked again,
until ``timeout``. A query that waited its whole time for a reply, or had replies of which none
proved the token (a robot refusing a control that does not prove it), is not asked again: it may
have reached the robot.

Every queryable on the key gets the query (``QueryTarget.ALL``) and every reply is read
(``ConsolidationMode.NONE``): a stranger's queryable declared "complete" on a robot's key would
otherwise be asked alone, or its reply kept instead of the robot's. Each query carries a nonce the
answer's proof covers (fsmscope/fleet/proofs.py), so an answer recorded for another query proves nothing."""

from __future__ import annotations

import queue
import secrets
import threading
import time
from typing import Callable

import zenoh

from . import proofs

RETRY_EVERY = 0.1  # seconds between two asks that reached nobody


def nonce() -> str:
    """A query's nonce: what the answer's proof must cover."""
    return secrets.token_hex(16)


def answer_proof(token: str, key: str, nonce: str, payload: bytes) -> bytes:
    """The robot's proof of its answer ``payload`` to the query on ``key`` with ``nonce``."""
    return proofs.sign(token, b"answer", key, nonce.encode(), payload)


def reply(query: zenoh.Query, token: str | None, payload: bytes, nonce: str | None = None) -> None:
    """The robot's answer to ``query``, with its proof over the query's nonce (its ``nonce`` parameter,
    unless given) when the robot has a token."""
    key = str(query.key_expr)
    said = nonce if nonce is not None else query.parameters.get("nonce") or ""
    query.reply(query.key_expr, payload,
                attachment=answer_proof(token, key, said, payload) if token else None)


def send(session: zenoh.Session, key: str, token: str | None, timeout: float, done: Callable[[bytes | None], None],
        parameters: str = "", payload: bytes | None = None, attachment: bytes | None = None,
        nonce_of: Callable[[str], str] = lambda said: said, cancel: zenoh.CancellationToken | None = None) -> None:
    """Ask ``key?parameters`` (with a new nonce) without waiting: ``done`` is called, in one of
    Zenoh's threads or a timer's, with the payload of the first reply that proves ``token``, or with
    None when none came within ``timeout`` or ``cancel`` was cancelled. ``nonce_of`` turns the
    query's nonce into the one the answer's proof covers (a control's answer covers the control's own
    proof instead). Its owner cancels ``cancel`` before it closes the session: a query still on its
    way when the interpreter ends would call back into Python from Zenoh's thread, which aborts."""
    deadline = time.monotonic() + timeout

    def once() -> None:
        started = time.monotonic()
        left = deadline - started
        said = nonce()
        covered = nonce_of(said).encode()
        found: list[bytes] = []
        heard = []  # replies that proved nothing: the query reached a queryable

        def replied(answer: zenoh.Reply) -> None:
            sample = answer.ok
            heard.append(True)
            if sample is None or found:
                return
            data = sample.payload.to_bytes()
            proof = sample.attachment.to_bytes() if sample.attachment is not None else None
            if proofs.proven(token, proof, b"answer", key, covered, data):
                found.append(data)
                done(data)

        def ended() -> None:
            if found:
                return
            now = time.monotonic()
            if heard or (cancel is not None and cancel.is_cancelled) or now - started >= left * 0.9 or deadline - now < RETRY_EVERY:
                done(None)  # refused, or it waited for an answer that did not come: the query reached something
                return
            timer = threading.Timer(RETRY_EVERY, once)
            timer.daemon = True
            timer.start()

        selector = "%s?%s" % (key, ";".join(filter(None, ("nonce=" + said, parameters))))
        try:
            session.get(selector, zenoh.handlers.Callback(replied, ended, indirect=False), payload=payload, attachment=attachment,
                        timeout=max(left, 0.01), target=zenoh.QueryTarget.ALL,
                        consolidation=zenoh.ConsolidationMode.NONE, cancellation_token=cancel)
        except zenoh.ZError:  # the session closed
            done(None)

    if not token:
        done(None)  # nothing could prove it
        return
    once()


def first_reply(session: zenoh.Session, key: str, token: str | None, timeout: float, parameters: str = "",
                payload: bytes | None = None, attachment: bytes | None = None,
                nonce_of: Callable[[str], str] = lambda said: said) -> bytes | None:
    """``send``, waiting for its answer: the payload of the first reply that proves ``token``; None
    when none came within ``timeout``."""
    answers: queue.SimpleQueue[bytes | None] = queue.SimpleQueue()
    send(session, key, token, timeout, answers.put, parameters, payload, attachment, nonce_of)
    try:
        return answers.get(timeout=timeout + 5)  # ``done`` comes at the query's end: never much later
    except queue.Empty:
        return None
