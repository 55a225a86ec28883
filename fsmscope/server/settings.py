"""What the app knows about how it is served: its token, where it listens, what it links to."""

from __future__ import annotations

from dataclasses import dataclass

MAX_BODY = 64 * 1024  # bytes: a request body over this is answered 413


@dataclass
class Settings:
    """Read by the Host check and body limit (fsmscope/server/middleware.py), the token checks (fsmscope/server/auth.py)
    and the routes (``scene_url``); ``port`` is None until the socket is bound."""

    token: str | None
    viewer_token: str | None = None  # watch only (fsmscope/server/auth.py)
    host: str = "127.0.0.1"
    port: int | None = None
    max_body: int = MAX_BODY
    scene_url: str | None = None  # a 3D view served beside the dashboard (the sim demo's viser), or None
