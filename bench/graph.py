"""Graph layout time (fsmscope/server/graph.py) for machines of 10, 100 and 1,000 states: cold and cached, medians.

    .venv/bin/python bench/graph.py [--repeat 3]

Shapes: 10 states flat; 100 states = 10 containers of 9; 1,000 states = 10 containers of 10 containers
of 9 (three levels), plus a flat-ish worst case: one root of 100 containers of 9. "default" is what
GET graph.svg draws without ?expand (all open up to 150 states, else the root only); "all open"
expands every container. Target: under 0.5 s cold for 1,000 states.
"""

import argparse
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from fsm.observation import structure  # noqa: E402
from fsmscope.server import graph  # noqa: E402
from fsmscope.server.hub import structure_hash  # noqa: E402


def leaf(parent, label):
    return {"label": label, "path": parent + "/" + label, "type": "CBState", "container": False,
            "outcomes": ["aborted", "succeeded"], "input_keys": [], "output_keys": [], "remapping": {}}


def machine(path, label, leaves, subs=()):
    """``leaves`` leaf states chained by 'succeeded', then the sub-containers; 'aborted' leaves the container."""
    kids = [leaf(path, "S%d" % i) for i in range(leaves)]
    kids += [machine(path + "/" + name, name, n, more) for name, n, more in subs]
    labels = [k["label"] for k in kids]
    transitions = []
    for i, label in enumerate(labels):
        nxt = labels[i + 1] if i + 1 < len(labels) else "succeeded"
        transitions.append({"from": label, "outcome": "succeeded", "to": nxt})
        transitions.append({"from": label, "outcome": "aborted", "to": "aborted"})
    return {"label": label, "path": path, "type": "StateMachine", "container": True,
            "outcomes": ["aborted", "succeeded"], "input_keys": [], "output_keys": [], "remapping": {},
            "initial": labels[:1], "children": kids, "transitions": transitions}


SHAPES = {
    "10 states": machine("/SM_ROOT", "SM_ROOT", 9),
    "100 states": machine("/SM_ROOT", "SM_ROOT", 0, [("SUB%d" % i, 9, ()) for i in range(10)]),
    "1,000 states (3 levels)": machine("/SM_ROOT", "SM_ROOT", 0, [
        ("SUB%d" % i, 0, [("SUB%d" % j, 9, ()) for j in range(10)]) for i in range(10)]),
    "1,000 states (root of 100)": machine("/SM_ROOT", "SM_ROOT", 0, [("SUB%d" % i, 9, ()) for i in range(100)]),
}


def measure(root, expand, repeat):
    key = structure_hash(root)
    n = structure.count(root)
    cold, cached, sizes, layouts = [], [], [], 0
    for _ in range(repeat):
        renderer = graph.Renderer()
        t = time.perf_counter()
        svg = renderer.render(root, key, expand, n)
        cold.append(time.perf_counter() - t)
        t = time.perf_counter()
        renderer.render(root, key, expand, n)
        cached.append(time.perf_counter() - t)
        sizes.append(len(svg))
        layouts = renderer.layouts
    return n, statistics.median(cold), statistics.median(cached), layouts, sizes[0]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    print("graph layout (dot per container, composed), median of %d, cores=%d" % (args.repeat, os.cpu_count()))
    print("%-28s %-9s %7s %10s %12s %8s %9s  %s" % ("machine", "drawn", "states", "cold s", "cached ms",
                                                   "layouts", "SVG KB", "target"))
    for name, root in SHAPES.items():
        all_open = [c["path"] for c in structure.containers(root)]
        for label, expand in (("default", None), ("all open", all_open)):
            n, cold, cached, layouts, size = measure(root, expand, args.repeat)
            target = ("<0.5 s cold: %s" % ("met" if cold < 0.5 else "MISSED")) if n >= 1000 else ""
            print("%-28s %-9s %7d %10.3f %12.3f %8d %9.0f  %s" % (name, label, n, cold, cached * 1000, layouts,
                                                                 size / 1024, target))


if __name__ == "__main__":
    main()
