"""The layering, kept by reading every import (ast), including those inside functions.

fsm is the runtime: the standard library only (orjson when installed) and nothing of the web or
the simulator. Inside fsm the core imports nothing but itself: it reports through its own seam
(fsm/core/reporting.py), which observation implements; no extension (ros, logfiles, debugging,
control) is imported by what it extends. sim never imports
server; interop (bags, MCAP, Foxglove) and fleet (Zenoh) import neither, ros2 (ROS 2 over DDS) none
of them; server imports sim, interop, fleet and ros2 only in its composition root, the CLI
(fsmscope/server/cli/). The ROS-free counterparts a script's run is given (fsmscope/counterparts/) import only fsm and themselves.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

OPTIONAL_FOR_FSM = {"orjson"}

# Which subpackages of fsm a module of each may import (pytransitions' rule: the core never
# imports an extension), each the ones it does import.
FSM_ARROWS = {
    "core": {"core"},
    "observation": {"observation", "core"},
    "ros": {"ros", "core", "observation"},
    "logfiles": {"logfiles", "observation"},
    "debugging": {"debugging", "observation", "core"},
    "control": {"control", "debugging", "observation"},
}

COMPOSITION_ROOT = ROOT / "fsmscope" / "server" / "cli"


def imported_modules(path: Path) -> list[tuple[int, str]]:
    """Every module a file imports, as absolute dotted names, with the line: relative imports
    are resolved against the file's own package."""
    package = list(path.relative_to(ROOT).parts[:-1])  # a module's package; an __init__'s is its own folder
    found = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - node.level + 1]
                module = ".".join(base + ([node.module] if node.module else []))
                if node.module is None:
                    found += [(node.lineno, "%s.%s" % (module, alias.name)) for alias in node.names]
                    continue
            else:
                module = node.module or ""
            found.append((node.lineno, module))
    return sorted(found)


def python_files(package: str) -> list[Path]:
    """The files of a package named by its dotted name."""
    return sorted((ROOT / package.replace(".", "/")).rglob("*.py"))


def where(path: Path, line: int, module: str) -> str:
    return "%s:%d imports %s" % (path.relative_to(ROOT), line, module)


def wrong_arrows_of_fsm(path: Path) -> list[str]:
    """What a module of fsm imports that it must not: outside the standard library, or a
    subpackage of fsm its own may not use."""
    own = path.relative_to(ROOT / "fsm").parts
    group = own[0] if len(own) > 1 else None
    wrong = []
    for line, module in imported_modules(path):
        top = module.split(".")[0]
        if top == "fsm":
            parts = module.split(".")
            target = parts[1] if len(parts) > 1 else None
            if group is not None and target in FSM_ARROWS and target not in FSM_ARROWS[group]:
                wrong.append(where(path, line, module))
        elif top not in sys.stdlib_module_names and top not in OPTIONAL_FOR_FSM and top != "__future__":
            wrong.append(where(path, line, module))
    return wrong


def imports_of(path: Path, package: str) -> list[str]:
    return [where(path, line, module) for line, module in imported_modules(path)
            if module == package or module.startswith(package + ".")]


def test_fsm_imports_only_the_standard_library_and_its_own_lower_layers():
    wrong = [arrow for path in python_files("fsm") for arrow in wrong_arrows_of_fsm(path)]
    assert wrong == []


# What each package beside fsm must never import: the server composes them, never the reverse.
SERVER, SIM, INTEROP, FLEET = "fsmscope.server", "fsmscope.sim", "fsmscope.interop", "fsmscope.fleet"
ROS1 = "fsmscope.ros1"  # the ROS 1 client: it uses interop's smach_msgs, nothing that composes it
ROS2 = "fsmscope.ros2"  # the ROS 2 client: its own messages, nothing that composes it
NEVER = {SIM: (SERVER,), INTEROP: (SERVER, SIM), FLEET: (SERVER, SIM, INTEROP), ROS1: (SERVER, SIM, FLEET),
         ROS2: (SERVER, SIM, INTEROP, FLEET)}


@pytest.mark.parametrize("package", sorted(NEVER))
def test_a_part_never_imports_the_parts_that_compose_it(package):
    wrong = [arrow for path in python_files(package) for other in NEVER[package]
             for arrow in imports_of(path, other)]
    assert wrong == []


@pytest.mark.parametrize("package", sorted(NEVER))
def test_the_server_imports_a_part_only_in_the_composition_root(package):
    wrong = [arrow for path in python_files(SERVER) if COMPOSITION_ROOT not in path.parents
             for arrow in imports_of(path, package)]
    assert wrong == []


def test_the_check_sees_a_wrong_arrow_inside_a_function(tmp_path, monkeypatch):
    fake_root = tmp_path
    module = fake_root / "fsm" / "core" / "bad.py"
    module.parent.mkdir(parents=True)
    module.write_text("def later():\n    from ..logfiles import recorder\n    import fastapi\n")
    monkeypatch.setattr(sys.modules[__name__], "ROOT", fake_root)
    assert wrong_arrows_of_fsm(module) == ["fsm/core/bad.py:2 imports fsm.logfiles",
                                           "fsm/core/bad.py:3 imports fastapi"]


def import_graph(package: str) -> dict[str, set[str]]:
    """Which of ``package``'s modules each of its modules imports (an ``__init__`` is its package's module)."""
    modules = {}
    for path in python_files(package):
        parts = list(path.relative_to(ROOT).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        modules[".".join(parts)] = path
    graph = {}
    for name, path in modules.items():
        targets = set()
        for _, module in imported_modules(path):
            while module and module not in modules:  # "from .routes import control" names a module or a name in one
                module = module.rpartition(".")[0]
            if module and module != name and not name.startswith(module + "."):  # a module's own package is no arrow
                targets.add(module)
        graph[name] = targets
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The import cycles of ``graph``: each strongly connected group of two or more modules, sorted (Tarjan's)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []

    def visit(node: str) -> None:
        index[node] = low[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for target in sorted(graph.get(node, ())):
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in on_stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            group = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                group.append(member)
                if member == node:
                    break
            if len(group) > 1:
                found.append(sorted(group))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return sorted(found)


@pytest.mark.parametrize("package", ["fsm", SERVER, FLEET, INTEROP, SIM, ROS1, ROS2])
def test_no_import_cycle_among_a_packages_modules(package):
    assert cycles(import_graph(package)) == []


def test_the_cycle_check_sees_a_cycle_through_a_function_and_type_checking(tmp_path, monkeypatch):
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "a.py").write_text("def later():\n    from . import b\n")
    (tmp_path / "pkg" / "b.py").write_text("from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .c import C\n")
    (tmp_path / "pkg" / "c.py").write_text("from pkg.a import later\n")
    (tmp_path / "pkg" / "d.py").write_text("from . import a\n")
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    assert cycles(import_graph("pkg")) == [["pkg.a", "pkg.b", "pkg.c"]]


def test_the_counterparts_of_ros_import_only_fsm_and_themselves():
    """fsmscope/counterparts/ stands in for smach, rospy... in a script's run: nothing of the server,
    the simulator, interop or the fleet is loaded with them."""
    own = "fsmscope.counterparts"
    wrong = [where(path, line, module) for path in python_files(own) for line, module in imported_modules(path)
             if module.split(".")[0] not in sys.stdlib_module_names | {"fsm", "__future__"}
             and module != own and not module.startswith(own + ".")]
    assert wrong == []
