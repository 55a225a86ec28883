"""Token, Host and Origin checks, and the request body limit.

``SecurityMiddleware`` is pure ASGI and outermost: it answers 400 for a foreign ``Host``
(DNS rebinding) and 413 for a body over the limit before any route runs, adds the hardening
headers to every HTTP response (errors included), and keeps the server's raw ``send`` in the
scope so a stalled websocket can be aborted. Route-level checks (token, Origin) are the
dependencies and helpers below.

The token travels only where the page puts it: an ``Authorization: Bearer`` header, a
websocket subprotocol ``fsmscope.token.TOKEN`` (browsers cannot set headers on a websocket),
or ``?token=`` for scripts. There is no cookie: cookies are not port-scoped, so one would be
sent to every other server on the host, and a second dashboard's would replace the first's.
"""

from __future__ import annotations

import ipaddress
import secrets
from dataclasses import dataclass, field
from typing import Any

from fastapi import HTTPException, Request, WebSocket

MAX_BODY = 64 * 1024
SUBPROTOCOL = "fsmscope"  # the websocket subprotocol the server answers with
TOKEN_SUBPROTOCOL = "fsmscope.token."  # followed by the token: how a browser's websocket carries it


def new_token() -> str:
    return secrets.token_urlsafe(24)


def is_loopback(host: str) -> bool:
    if host in ("localhost",):
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def check_bind(host: str, token: str | None) -> None:
    """Refuse to listen beyond this machine without a token."""
    if not token and not is_loopback(host):
        raise ValueError("refusing to bind %s without a token: the dashboard can stop a machine" % host)


@dataclass
class Settings:
    """What the checks need to know about the server; ``port`` is set once the socket is bound."""

    token: str | None
    host: str = "127.0.0.1"
    port: int | None = None
    max_body: int = MAX_BODY
    extra_hosts: set[str] = field(default_factory=set)

    def host_names(self) -> set[str]:
        names = {"127.0.0.1", "localhost", "::1", "[::1]"} | self.extra_hosts
        if self.host not in ("0.0.0.0", "::", ""):
            names.add(self.host)
            if ":" in self.host:
                names.add("[%s]" % self.host)
        return names

    def host_ok(self, host_header: str | None) -> bool:
        if not host_header:
            return False
        host, port = _split_host(host_header)
        if self.host in ("0.0.0.0", "::", ""):
            ok_name = True  # bound everywhere: the token is the guard; still refuse nonsense below
        else:
            ok_name = host.lower() in self.host_names()
        if not ok_name:
            return False
        return self.port is None or port == self.port

    def token_ok(self, candidate: str | None) -> bool:
        if not self.token:
            return True
        return bool(candidate) and secrets.compare_digest(candidate.encode(), self.token.encode())


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


def own_origin(host_header: str | None) -> str:
    return "http://%s" % (host_header or "")


def _bearer(headers: Any) -> str | None:
    auth = headers.get("authorization")
    if auth and auth[:7].lower() == "bearer ":
        return auth[7:].strip()
    return None


class SecurityMiddleware:
    """Host check for HTTP and websockets, body size limit, raw ``send`` for aborting stalled sockets."""

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
        if not self.settings.host_ok(headers.get("host")):
            if kind == "http":
                await _json(send, 400, "invalid Host header")
            else:
                await _ws_deny(scope, send, 400, "invalid Host header")
            return
        if kind == "websocket":
            scope["fsmscope.raw_send"] = send
            await self.app(scope, receive, send)
            return
        if scope["method"] in ("POST", "PUT", "PATCH", "DELETE"):
            limit = self.settings.max_body
            length = headers.get("content-length")
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
            return
        await self.app(scope, receive, send)


# No other site may frame the dashboard (a Preempt button under someone else's page), sniff
# a type, or learn our URL (it carries the token) from a Referer.
_HARDENING = [(b"x-frame-options", b"DENY"), (b"content-security-policy", b"frame-ancestors 'none'"),
              (b"x-content-type-options", b"nosniff"), (b"referrer-policy", b"no-referrer")]


def _hardened(send: Any) -> Any:
    async def hardened_send(message: dict) -> None:
        if message["type"] == "http.response.start":
            message = dict(message, headers=list(message.get("headers", ())) + _HARDENING)
        await send(message)
    return hardened_send


async def _json(send: Any, status: int, detail: str) -> None:
    import orjson

    body = orjson.dumps({"detail": detail})
    await send({"type": "http.response.start", "status": status,
                "headers": [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())]})
    await send({"type": "http.response.body", "body": body})


async def _ws_deny(scope: dict, send: Any, status: int, detail: str) -> None:
    """Refuse a websocket handshake with an HTTP status when the server can, else a 403 close."""
    import orjson

    if "websocket.http.response" in (scope.get("extensions") or {}):
        body = orjson.dumps({"detail": detail})
        await send({"type": "websocket.http.response.start", "status": status,
                    "headers": [(b"content-type", b"application/json"),
                                (b"content-length", str(len(body)).encode())]})
        await send({"type": "websocket.http.response.body", "body": body})
    else:
        await send({"type": "websocket.close", "code": 1008})


async def deny_websocket(websocket: WebSocket, status: int, detail: str) -> None:
    await _ws_deny(websocket.scope, websocket._send, status, detail)


# Route checks.

def require_token(request: Request) -> None:
    """Dependency for everything under /api but health: 403 for a state change from another
    origin, 401 without a valid token (Authorization: Bearer or ?token=)."""
    settings: Settings = request.app.state.settings
    origin = request.headers.get("origin")
    if request.method != "GET" and origin is not None and origin != own_origin(request.headers.get("host")):
        raise HTTPException(403, "cross-origin request refused")
    if not settings.token_ok(_bearer(request.headers) or request.query_params.get("token")):
        raise HTTPException(401, "a valid token is required (Authorization: Bearer or ?token=)")


def websocket_token(websocket: WebSocket) -> str | None:
    """The token a websocket carries: its subprotocol, a Bearer header, or ?token=."""
    offered = websocket.headers.get("sec-websocket-protocol", "")
    for protocol in offered.split(","):
        protocol = protocol.strip()
        if protocol.startswith(TOKEN_SUBPROTOCOL):
            return protocol[len(TOKEN_SUBPROTOCOL):]
    return _bearer(websocket.headers) or websocket.query_params.get("token")


def websocket_subprotocol(websocket: WebSocket) -> str | None:
    """The subprotocol to accept with: ours when the client offered it (a browser must be answered
    with one it offered), else none."""
    offered = [p.strip() for p in websocket.headers.get("sec-websocket-protocol", "").split(",")]
    return SUBPROTOCOL if SUBPROTOCOL in offered else None


def websocket_refusal(websocket: WebSocket) -> tuple[int, str] | None:
    """Origin (before accept) and token checks for a websocket; None when it may be accepted."""
    settings: Settings = websocket.app.state.settings
    origin = websocket.headers.get("origin")
    if origin is not None and origin != own_origin(websocket.headers.get("host")):
        return 403, "websocket from a foreign origin refused"
    if not settings.token_ok(websocket_token(websocket)):
        return 401, "a valid token is required"
    return None
