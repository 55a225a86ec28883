"""A container's states wrapped into rows, so that its drawing is about as wide as a screen is.

dot draws a machine's flow top to bottom, one rank per step: a sequence of 30 states is a column
thirty boxes tall (2,300 points), whose labels no screen shows readable whole. Here the steps of a
container are ranked (a longest path from its initial state, loops left out) and consecutive ranks
are grouped into rows, each drawn left to right (a ``rank=same`` subgraph: dot lays a row's edges
out as flat ones), the rows top to bottom like the lines of a text. How many ranks a row holds is
chosen by the drawing's fit to a box of ASPECT (width / height, a landscape graph pane): the sizes
of every choice are estimated here, and the rows of a choice put into its dot graph (make_rows);
fsmscope/server/graph.py has dot lay the few best out and keeps the one that fits best (dot routes edges
around rows as it likes). One rank a row is dot's own drawing.
"""

from __future__ import annotations

import pydot

ASPECT = 1.5  # width / height of the box a drawing is made to fit: the graph pane of a laptop's page
CHAR_PT = 7.6  # a label's width per character (12 pt Times, mostly capitals)
NODE_PAD_PT = 18.0  # a box's margins around its label
MIN_NODE_W = 54.0  # dot's smallest box: 0.75 inch
NODE_H = 29.0  # a box: 0.4 inch (fsmscope/server/graph.py)
EDGE_CHAR_PT = 5.0  # an edge label's width per character (9 pt)
GAP_PT = 40.0  # between two boxes of a row: nodesep, an arrow and its label
ROW_GAP_PT = 36.0  # between two rows: ranksep and an edge label
OUTCOME_ROW_PT = 60.0  # the outcomes' row at the bottom, with its gap


def ranks(children: list[str], initial: list[str], edges: list[tuple[str, str]]) -> dict[str, int]:
    """Each child's rank: the longest path to it from the initial states, then from the others in
    order, the edges that loop back (found by a depth-first walk) left out."""
    out: dict[str, list[str]] = {c: [] for c in children}
    for a, b in edges:
        out[a].append(b)
    colour: dict[str, int] = {}  # 1: on the walk's path, 2: done
    order: list[str] = []
    back: set[tuple[str, str]] = set()
    for start in [*initial, *children]:
        if start not in out or start in colour:
            continue
        colour[start] = 1
        stack = [(start, iter(out[start]))]
        while stack:
            node, todo = stack[-1]
            nxt = next(todo, None)
            if nxt is None:
                colour[node] = 2
                order.append(node)
                stack.pop()
            elif colour.get(nxt) == 1:
                back.add((node, nxt))
            elif nxt not in colour:
                colour[nxt] = 1
                stack.append((nxt, iter(out[nxt])))
    rank = {c: 0 for c in children}
    for node in reversed(order):  # a topological order of the edges that do not loop back
        for nxt in out[node]:
            if (node, nxt) not in back:
                rank[nxt] = max(rank[nxt], rank[node] + 1)
    return rank


def node_size(label: str, size: tuple[float, float] | None) -> tuple[float, float]:
    """A child's estimated drawn size: an open container's drawing, else a box around its label."""
    if size is not None:
        return size
    return max(MIN_NODE_W, len(label) * CHAR_PT + NODE_PAD_PT), NODE_H


def fit_score(width: float, height: float) -> float:
    """How big a drawing of this size is shown in a box of ASPECT (the larger, the more readable)."""
    return min(ASPECT / width, 1 / height)


def row_choices(rank: dict[str, int], sizes: dict[str, tuple[float, float]], flat_label: dict[str, float],
                outcomes: int, count: int) -> list[int]:
    """The ``count`` numbers of ranks a row holds whose estimated drawings best fit a box of ASPECT,
    best first (1: dot's own column); ``flat_label``: the width of the widest label of an edge out of
    each child (drawn beside it when the edge is flat). An estimate: dot routes edges around rows as
    it likes, so the caller lays the first few out and keeps the best."""
    depth = max(rank.values(), default=-1) + 1
    scored = []
    for k in range(1, depth + 1):
        rows: dict[int, list[str]] = {}
        for child, r in rank.items():
            rows.setdefault(r // k, []).append(child)
        width = max(sum(sizes[c][0] + GAP_PT + (flat_label[c] if k > 1 else 0) for c in row) for row in rows.values())
        height = sum(max(sizes[c][1] for c in row) for row in rows.values()) + ROW_GAP_PT * (len(rows) - 1)
        if outcomes:
            height += OUTCOME_ROW_PT
        scored.append((-fit_score(width, height), k))
    return [k for _, k in sorted(scored)[:count]] or [1]


def ranking(node: dict, sizes: dict[str, tuple[float, float]]) -> tuple[dict[str, int], dict[str, tuple[float, float]], dict[str, float]]:
    """A container's states (by label): their ranks, estimated sizes and widest outgoing edge label."""
    children = node.get("children") or ()
    labels = {c["label"] for c in children}
    edges, widest = [], {c["label"]: 0.0 for c in children}
    for tr in node.get("transitions") or ():
        if tr["from"] not in labels:
            continue
        widest[tr["from"]] = max(widest[tr["from"]], len(tr["outcome"]) * EDGE_CHAR_PT)
        if tr.get("to") in labels:
            edges.append((tr["from"], tr["to"]))
    initial = [label for label in node.get("initial") or () if label in labels]
    rank = ranks(list(widest), initial, edges)
    return rank, {c["label"]: node_size(c["label"], sizes.get(c["path"])) for c in children}, widest


def row_options(node: dict, sizes: dict[str, tuple[float, float]], count: int) -> list[int]:
    """The ``count`` best estimated numbers of ranks a row of the container holds."""
    rank, boxes, widest = ranking(node, sizes)
    return row_choices(rank, boxes, widest, len(node.get("outcomes") or ()), count)


def make_rows(g: pydot.Dot, node: dict, names: dict[str, str], per_row: int) -> dict[str, int] | None:
    """Wrap the container's states into rows of ``per_row`` ranks in its graph ``g``: each
    state's row (by dot name), a row's first state kept under the one above it; None: no rows."""
    if per_row <= 1:
        return None
    rank = {names[label]: r for label, r in ranking(node, {})[0].items()}
    g.set("ranksep", "0.25")  # the rows' edges are labelled beside them (below): no rank of labels between rows
    row_of = {name: r // per_row for name, r in rank.items()}
    heads = []
    for row in range(max(row_of.values()) + 1):
        band = pydot.Subgraph(rank="same")
        members = sorted((name for name in row_of if row_of[name] == row), key=lambda name: rank[name])
        for name in members:
            band.add_node(pydot.Node(name))
        g.add_subgraph(band)
        heads.append(members[0])
    for above, below in zip(heads, heads[1:]):  # the rows aligned on the left, as lines of text are
        g.add_edge(pydot.Edge(above, below, style="invis", weight="10"))
    return row_of
