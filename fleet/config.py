"""A Zenoh session's configuration from what a user says: peer mode (the default) or client of a
router, explicit endpoints to listen on and connect to, and multicast scouting (LAN discovery) only
when asked: by default a session finds nobody it was not told about."""

from __future__ import annotations

import json
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
    return config


def read_config_file(path: str) -> zenoh.Config:
    """The Zenoh configuration in the file at ``path``; ValueError saying why when it cannot be used."""
    try:
        return zenoh.Config.from_file(path)
    except zenoh.ZError as exc:
        raise ValueError("cannot use %s as a Zenoh configuration: %s" % (path, exc)) from None
