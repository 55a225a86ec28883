"""A Zenoh session's configuration from what a user says: peer mode (the default) or client of a
router, explicit endpoints to listen on and connect to, and multicast scouting (LAN discovery) only
when asked: by default a session finds nobody it was not told about, and listens nowhere it was not
told to (Zenoh's own default has a peer listen on every interface, on a free port)."""

from __future__ import annotations

import json
import re
from typing import Sequence

import zenoh

LEASE_MS = 3000  # a link silent this long is dropped: the machines behind it are seen gone (Zenoh: 10 s)


def session_config(connect: Sequence[str] = (), listen: Sequence[str] = (), mode: str = "peer",
                   scouting: bool = False, config_file: str | None = None) -> zenoh.Config:
    """``connect`` / ``listen``: endpoints such as ``tcp/127.0.0.1:7447``; ``mode``: "peer" or
    "client" (through a zenohd router), or "router" (routes for its clients, as zenohd does: the
    tests' stand-in for zenohd, which is not a Python package); ``scouting``: find peers on the LAN
    by multicast; ``config_file``: a Zenoh configuration file (JSON5) for what has no option here, such
    as TLS certificates (``tls/`` endpoints) or access control, the options above applied over it."""
    if mode not in ("peer", "client", "router"):
        raise ValueError("mode must be peer, client or router, not %r" % mode)
    config = read_config_file(config_file) if config_file else zenoh.Config()
    config.insert_json5("mode", json.dumps(mode))
    config.insert_json5("scouting/multicast/enabled", json.dumps(scouting))
    config.insert_json5("transport/link/tx/lease", json.dumps(LEASE_MS))
    if connect:
        config.insert_json5("connect/endpoints", json.dumps(list(connect)))
    if listen:
        config.insert_json5("listen/endpoints", json.dumps(list(listen)))
    elif not scouting and config.get_json("listen/endpoints") == zenoh.Config().get_json("listen/endpoints"):
        # Nobody said where to listen: nowhere (the session connects where it is told). Multicast
        # discovery needs a listener, and a configuration file's own endpoints are the user's word.
        config.insert_json5("listen/endpoints", "[]")
    return config


def open_session(connect: Sequence[str] = (), listen: Sequence[str] = (), mode: str = "peer",
                 scouting: bool = False, config_file: str | None = None) -> zenoh.Session:
    """A session configured as ``session_config`` says; ValueError saying why when Zenoh cannot open
    it (an endpoint it cannot parse, a port taken, no router to connect to as its client)."""
    try:
        return zenoh.open(session_config(connect, listen, mode, scouting, config_file))
    except zenoh.ZError as exc:
        raise ValueError("cannot open a Zenoh session: %s" % said(exc)) from None


def said(exc: zenoh.ZError) -> str:
    """What a Zenoh error says, without the places in Zenoh's Rust sources it carries."""
    text = str(exc)
    inner = re.search(r'msg: "(.*?)", location', text)
    return re.sub(r"\s+at /\S+?\.rs:\d+\.?", "", inner.group(1) if inner else text).strip()


def read_config_file(path: str) -> zenoh.Config:
    """The Zenoh configuration in the file at ``path``; ValueError saying why when it cannot be used."""
    try:
        return zenoh.Config.from_file(path)
    except zenoh.ZError as exc:
        raise ValueError("cannot use %s as a Zenoh configuration: %s" % (path, said(exc))) from None
