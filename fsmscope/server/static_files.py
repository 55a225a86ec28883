"""Where the dashboard's files are: served by the server (fsmscope/server/routes/pages.py) and inlined into an
exported page (fsmscope/server/export_html.py), which needs no web framework to find them."""

from __future__ import annotations

import importlib.util


def static_dir() -> str | None:
    """Where the dashboard's files are (the ``static`` package), or None when it is not installed."""
    spec = importlib.util.find_spec("fsmscope.static")
    if spec is None or not spec.submodule_search_locations:
        return None
    return list(spec.submodule_search_locations)[0]
