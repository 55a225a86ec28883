"""The outermost layer of the app: the Host check, the request body limit, the hardening headers.

``SecurityMiddleware`` is pure ASGI and wraps everything, even the handler that answers 500
(``app._App.build_middleware_stack``): it answers 400 for a foreign ``Host`` (DNS rebinding)
and 413 for a body over the limit before any route runs, and adds the hardening headers to
every HTTP response, errors included. The token and Origin checks are the routes' (fsmscope/server/auth.py).

Nobody unauthenticated can fill the terminal by knocking. Every refused websocket handshake goes
through ``deny_handshake``, quietly: uvicorn's sans-I/O websocket writes an ERROR line ("ASGI
callable returned without completing handshake") for each handshake answered with an HTTP status.
``deny_handshake`` marks the refusal in the request's context (uvicorn writes its line in the same
task), and ``QUIET_CLIENTS``, on uvicorn's logger, drops that line for a marked handshake only (a
handshake the app failed to finish for another reason is still said). uvicorn's warnings about
a client's malformed request (not HTTP, an unknown upgrade) it lets through once a minute each.
"""

from __future__ import annotations

import logging
import time
from contextvars import ContextVar
from typing import Any

import orjson

from .settings import Settings

_ANY_ADDRESS = ("0.0.0.0", "::", "")

# No other site may frame the dashboard (a Preempt button under someone else's page), sniff
# a type, or learn our URL (it carries the token) from a Referer.
_HARDENING = [(b"x-frame-options", b"DENY"), (b"content-security-policy", b"frame-ancestors 'none'"),
              (b"x-content-type-options", b"nosniff"), (b"referrer-policy", b"no-referrer")]


def host_names(settings: Settings) -> set[str]:
    """The names a request's Host header may give when the server listens on one address."""
    names = {"127.0.0.1", "localhost", "::1", "[::1]"}
    if settings.host not in _ANY_ADDRESS:
        names.add(settings.host)
        if ":" in settings.host:
            names.add("[%s]" % settings.host)
    return names


def host_ok(settings: Settings, host_header: str | None) -> bool:
    if not host_header:
        return False
    host, port = _split_host(host_header)
    # Bound to every address, any name will do (the token is the guard); the port must still be ours.
    if settings.host not in _ANY_ADDRESS and host.lower() not in host_names(settings):
        return False
    return settings.port is None or port == settings.port


def _split_host(value: str) -> tuple[str, int | None]:
    value = value.strip()
    if value.startswith("["):
        end = value.find("]")
        host, rest = value[:end + 1], value[end + 1:]
    elif value.count(":") == 1:
        host, rest = value.split(":")[0], ":" + value.split(":")[1]
    else:
        host, rest = value, ""
    port = None
    if rest.startswith(":"):
        try:
            port = int(rest[1:])
        except ValueError:
            port = -1
    return host, port if port is not None else 80


class SecurityMiddleware:
    """Host check for HTTP and websockets, body size limit and hardening headers for HTTP."""

    def __init__(self, app: Any, settings: Settings) -> None:
        self.app = app
        self.settings = settings

    async def __call__(self, scope: dict, receive: Any, send: Any) -> None:
        kind = scope["type"]
        if kind not in ("http", "websocket"):
            await self.app(scope, receive, send)
            return
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope.get("headers", ())}
        if kind == "http":
            send = _hardened(send)
        if not host_ok(self.settings, headers.get("host")):
            if kind == "http":
                await _json(send, 400, "invalid Host header")
            else:
                await deny_handshake(scope, send, 400, "invalid Host header")
            return
        if kind == "http" and scope["method"] in ("POST", "PUT", "PATCH", "DELETE"):
            await self._limited(scope, receive, send, headers.get("content-length"))
            return
        await self.app(scope, receive, send)

    async def _limited(self, scope: dict, receive: Any, send: Any, length: str | None) -> None:
        """Read the whole body (refusing it past the limit), then hand it to the app."""
        limit = self.settings.max_body
        if length is not None:
            try:
                too_big = int(length) > limit
            except ValueError:
                await _json(send, 400, "invalid Content-Length")
                return
            if too_big:
                await _json(send, 413, "request body over %d bytes" % limit)
                return
        body = bytearray()
        while True:
            message = await receive()
            if message["type"] != "http.request":
                return  # the client left
            body += message.get("body", b"")
            if len(body) > limit:
                await _json(send, 413, "request body over %d bytes" % limit)
                return
            if not message.get("more_body"):
                break
        replayed = False

        async def replay() -> dict:
            nonlocal replayed
            if not replayed:
                replayed = True
                return {"type": "http.request", "body": bytes(body), "more_body": False}
            return await receive()

        await self.app(scope, replay, send)


def _hardened(send: Any) -> Any:
    async def hardened_send(message: dict) -> None:
        if message["type"] == "http.response.start":
            message = dict(message, headers=list(message.get("headers", ())) + _HARDENING)
        await send(message)
    return hardened_send


def _error(detail: str) -> tuple[list[tuple[bytes, bytes]], bytes]:
    """The headers and body of a refusal: JSON ``{"detail": ...}``, like every error of the app."""
    body = orjson.dumps({"detail": detail})
    return [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())], body


async def _json(send: Any, status: int, detail: str) -> None:
    headers, body = _error(detail)
    await send({"type": "http.response.start", "status": status, "headers": headers})
    await send({"type": "http.response.body", "body": body})


_refused: ContextVar[bool] = ContextVar("fsmscope_refused_handshake", default=False)
UNFINISHED = "ASGI callable returned without completing handshake."  # uvicorn's words
MALFORMED = ("Invalid HTTP request received.", "Unsupported upgrade request.")  # uvicorn's, about a client
MALFORMED_EVERY = 60.0  # s: each said at most once in this long


class _QuietClients(logging.Filter):
    """On uvicorn's logger: no line for a handshake refused on purpose, at most one a minute for
    each kind of malformed request."""

    def __init__(self) -> None:
        super().__init__()
        self._said: dict[str, float] = {}

    def filter(self, record: logging.LogRecord) -> bool:
        if record.msg == UNFINISHED:
            return not _refused.get()
        if record.msg in MALFORMED:
            now = time.monotonic()
            if now - self._said.get(record.msg, -MALFORMED_EVERY) < MALFORMED_EVERY:
                return False
            self._said[record.msg] = now
            record.msg = "%s (said at most once a minute)" % record.msg
        return True


QUIET_CLIENTS = _QuietClients()


async def deny_handshake(scope: dict, send: Any, status: int, detail: str) -> None:
    """Refuse a websocket handshake with an HTTP status when the server can, else a 403 close."""
    _refused.set(True)
    if "websocket.http.response" in (scope.get("extensions") or {}):
        headers, body = _error(detail)
        await send({"type": "websocket.http.response.start", "status": status, "headers": headers})
        await send({"type": "websocket.http.response.body", "body": body})
    else:
        await send({"type": "websocket.close", "code": 1008})
