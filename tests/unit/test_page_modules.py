"""A page names every ES module its script needs in <link rel="modulepreload">: the browser then fetches
them all at once instead of one level of imports after another (about 0.6 s of a page's first graph,
bench/big_machine_browser.py). Dynamic imports (``import(...)``) are loaded when used and not preloaded."""

import pathlib
import re

STATIC = pathlib.Path(__file__).resolve().parents[2] / "fsmscope" / "static"
IMPORT = re.compile(r'^\s*(?:import|export)\b[^;]*?\bfrom\s+"\./([\w.]+\.js)"', re.M | re.S)
PRELOAD = re.compile(r'<link rel="modulepreload" href="([\w.]+\.js)">')


def imported_by(module: str) -> set[str]:
    """Every module ``module`` imports statically, transitively."""
    seen: set[str] = set()
    todo = [module]
    while todo:
        for name in IMPORT.findall((STATIC / todo.pop()).read_text()):
            if name not in seen:
                seen.add(name)
                todo.append(name)
    return seen


def test_the_page_preloads_exactly_the_modules_app_js_imports():
    preloaded = PRELOAD.findall((STATIC / "index.html").read_text())
    assert sorted(preloaded) == sorted(imported_by("app.js"))


def test_the_fleet_page_preloads_exactly_the_modules_fleet_js_imports():
    preloaded = PRELOAD.findall((STATIC / "fleet.html").read_text())
    assert sorted(preloaded) == sorted(imported_by("fleet.js"))

