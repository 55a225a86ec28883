"""The page's own modules run in Node, for the tests that check a Python rule and its generated
JavaScript mirror give the same answers (skipped where Node is not installed)."""

from __future__ import annotations

import json
import shutil
import subprocess

import pytest
from fsmscope.server.schema_export import JS_PATH

needs_node = pytest.mark.skipif(shutil.which("node") is None, reason="node is not installed")


def map_in_schema_js(function: str, items: list) -> list:
    """``items.map(function)`` in Node, where ``function`` (JavaScript) sees fsmscope/static/schema.js as ``m``."""
    program = "import(%s).then(m => console.log(JSON.stringify(%s.map(%s))))" % (
        json.dumps("file://" + JS_PATH), json.dumps(items), function)
    done = subprocess.run(["node", "--input-type=module", "-e", program], capture_output=True, text=True, timeout=30)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)
