"""Who may use the server: the tokens and their roles, the bind policy, and the token and Origin
checks of the routes.

Two tokens: the operator's (watch and control) and a viewer's (watch only: every GET and the
stream, no control, no publishing), so that a view can be shared without handing out the controls.

The token travels only where the page puts it: an ``Authorization: Bearer`` header, a
websocket subprotocol ``fsmscope.token.TOKEN`` (browsers cannot set headers on a websocket),
or ``?token=`` for scripts. There is no cookie: cookies are not port-scoped, so one would be
sent to every other server on the host, and a second dashboard's would replace the first's.
"""

from __future__ import annotations

import ipaddress
import secrets
from typing import Any

from fastapi import HTTPException, Request, WebSocket

from .settings import Settings

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


OPERATOR, VIEWER = "operator", "viewer"


def _same(candidate: str | None, token: str | None) -> bool:
    return bool(candidate) and bool(token) and secrets.compare_digest(candidate.encode(), token.encode())


def role_of(settings: Settings, candidate: str | None) -> str | None:
    """What a token makes its bearer: the operator (the token: watch and control), a viewer (the
    viewer token: watch only), or nobody (None). Without a token everyone is the operator."""
    if not settings.token or _same(candidate, settings.token):
        return OPERATOR
    if _same(candidate, settings.viewer_token):
        return VIEWER
    return None


def own_origin(host_header: str | None) -> str:
    return "http://%s" % (host_header or "")


def _bearer(headers: Any) -> str | None:
    auth = headers.get("authorization")
    if auth and auth[:7].lower() == "bearer ":
        return auth[7:].strip()
    return None


def require_token(request: Request) -> str:
    """Dependency for everything under /api but health: 403 for a state change from another
    origin, 401 without a valid token (Authorization: Bearer or ?token=); returns the role."""
    settings: Settings = request.app.state.settings
    origin = request.headers.get("origin")
    if request.method != "GET" and origin is not None and origin != own_origin(request.headers.get("host")):
        raise HTTPException(403, "cross-origin request refused")
    role = role_of(settings, _bearer(request.headers) or request.query_params.get("token"))
    if role is None:
        raise HTTPException(401, "a valid token is required (Authorization: Bearer or ?token=)")
    return role


VIEWER_REFUSAL = "this token is a viewer's: it may watch, not control (the operator's token may)"


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


def websocket_refusal(websocket: WebSocket, operator: bool = False) -> tuple[int, str] | None:
    """Origin (before accept) and token checks for a websocket; None when it may be accepted.
    ``operator``: the socket controls (a publisher's ingest), so a viewer's token is refused."""
    settings: Settings = websocket.app.state.settings
    origin = websocket.headers.get("origin")
    if origin is not None and origin != own_origin(websocket.headers.get("host")):
        return 403, "websocket from a foreign origin refused"
    role = role_of(settings, websocket_token(websocket))
    if role is None:
        return 401, "a valid token is required"
    if operator and role != OPERATOR:
        return 403, "this token is a viewer's: it may watch, not publish"
    return None
