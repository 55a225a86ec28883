"""A machine's graph as SVG: each container laid out on its own by Graphviz dot, composed bottom-up.

Laying out a whole hierarchy as one graph explodes (1,000 states took minutes); here every
open container is a graph of its own in which a child container is one node: a plain box
when closed, a fixed-size box the size of the child's finished drawing when open. The
child's drawing is then put in that box's place. Graphs are built with pydot's API (never
by parsing DOT); the containers of one depth are laid out at once by the kept ``dot``
processes (fsmscope/server/dot.py). Ids follow docs/api.md: ``s:PATH`` (state), ``o:PATH:OUTCOME``
(container outcome), ``e:PATH:FROM:OUTCOME`` (edge), ``c:PATH`` (open container).

Results are cached per (structure hash, set of open containers); a composed container is
also cached on its own, serialized, so opening one more container lays out and serializes only it
and its ancestors (the document is the cached pieces joined).
"""

from __future__ import annotations

import collections
import concurrent.futures
import os
import re
import threading
import xml.etree.ElementTree as ET
from typing import Iterable

import pydot

from fsm.observation import structure
from fsm.observation.schema import container_id, edge_id, outcome_id, state_id
from fsm.observation.visible import visible

from .dot import DotError, DotPool
from .graph_rows import fit_score, make_rows, row_options

SVG_NS = "http://www.w3.org/2000/svg"
XLINK_NS = "http://www.w3.org/1999/xlink"
ET.register_namespace("", SVG_NS)
ET.register_namespace("xlink", XLINK_NS)
_G = "{%s}g" % SVG_NS
_POLYGON = "{%s}polygon" % SVG_NS
_TITLE = "{%s}title" % SVG_NS
# dot prefixes the ids of every graph after the first one a process lays out (and of pages) with this:
# the contract's ids (docs/api.md) are without.
_PAGE = re.compile(r"^page\d+,\d+_(?=[scoe]:)")
_HOLE = re.compile(rb"<!--fsmscope-child-(\d+)-->")  # where an open child's drawing goes in its parent's text
# A piece's own declarations: the document's root declares them once. Only these two: dot writes no other.
_DECLARATIONS = re.compile(rb' xmlns(?::xlink)?="(?:%s|%s)"' % (SVG_NS.encode(), XLINK_NS.encode()))

# A composed container: its serialized drawing as text pieces and, between them, the path of the open
# child whose drawing goes there; its width and height in points.
Part = tuple[list[bytes | str], float, float]

AUTO_OPEN_LIMIT = 150   # without ``expand``: every container open up to this many states, else only the root
ROW_TRIALS = 6          # drawings of a container in rows laid out to keep the best, up to AUTO_OPEN_LIMIT states
DOT_TIMEOUT = 60.0
BIG_CONTAINER = 40      # children above which edges are straight lines with external labels
LABEL_PT = 12           # a state's label, in points (fsmscope/static/graph_geometry.js reads the drawing's scale from it)
NODE_HEIGHT_IN = 0.4    # a state's box: its label and a little air


class GraphError(Exception):
    """Graphviz failed or is missing."""


def q(text: str) -> str:
    """A DOT double-quoted string: never an HTML label, no escape sequences of dot's own. XML cannot
    hold control characters (Graphviz would write them raw): each shows as its sign
    (fsm.observation.visible); ids are percent-escaped by fsm.observation.schema."""
    return '"%s"' % visible(text).replace("\\", "\\\\").replace('"', '\\"')


def open_set(root: dict, expand: Iterable[str] | None, n_states: int) -> frozenset[str]:
    """The containers drawn open: the root, and those named (whose parents are open too)."""
    if not expand:
        if n_states <= AUTO_OPEN_LIMIT:
            return frozenset(c["path"] for c in structure.containers(root))
        return frozenset([root["path"]])
    wanted = set(expand) | {root["path"]}
    reached = structure.containers(root, lambda c: c["path"] in wanted)
    return frozenset(c["path"] for c in reached if c["path"] in wanted)


def described(node: dict) -> str:
    """What a state's or container's title (its tooltip) says: its path and class, never a Graphviz name."""
    return visible("%s (%s)" % (node["path"], node.get("type", "")))


def build_dot(node: dict, sizes: dict[str, tuple[float, float]], per_row: int = 1) -> tuple[pydot.Dot, dict[str, str]]:
    """One container's graph, and the title of each element by id (dot would title them by its own
    node names, "n12"); ``sizes`` gives the drawing size (points) of each open child container;
    ``per_row``: how many ranks of its states a row holds (fsmscope/server/graph_rows.py; 1: dot's own column)."""
    path = node["path"]
    titles = {container_id(path): described(node)}
    g = pydot.Dot(q(path), graph_type="digraph")
    g.set("id", q(container_id(path)))
    g.set("label", q(node["label"] + " (" + node.get("type", "") + ")"))
    g.set("labelloc", "t")
    g.set("fontsize", "12")
    g.set("nodesep", "0.3")
    g.set("ranksep", "0.4")
    g.set_node_defaults(fontsize=str(LABEL_PT), shape="box", style="rounded", height=str(NODE_HEIGHT_IN))
    g.set_edge_defaults(fontsize="9")
    big = len(node.get("children") or ()) > BIG_CONTAINER
    if big:  # dot's spline routing and label placement grow fast with long edges: keep big graphs cheap
        g.set("splines", "line")
    names: dict[str, str] = {}
    for i, child in enumerate(node.get("children") or ()):
        name = "n%d" % i
        names[child["label"]] = name
        cpath = child["path"]
        titles[state_id(cpath)] = described(child)
        if cpath in sizes:
            w, h = sizes[cpath]
            g.add_node(pydot.Node(name, id=q(state_id(cpath)), label=q(""), shape="box", style="solid", color="transparent",
                                  fixedsize="true", width="%.4f" % (w / 72.0), height="%.4f" % (h / 72.0)))
        elif child.get("container"):
            g.add_node(pydot.Node(name, id=q(state_id(cpath)), label=q(child["label"]), shape="box3d", style="solid",
                                  **{"class": q("container")}))
        else:
            g.add_node(pydot.Node(name, id=q(state_id(cpath)), label=q(child["label"]), **{"class": q("state")}))
    outcome_nodes: dict[str, str] = {}

    def outcome_node(outcome: str) -> str:
        name = outcome_nodes.get(outcome)
        if name is None:
            name = outcome_nodes[outcome] = "o%d" % len(outcome_nodes)
            titles[outcome_id(path, outcome)] = visible("%s: outcome %s" % (path, outcome))
            g.add_node(pydot.Node(name, id=q(outcome_id(path, outcome)), label=q(outcome), shape="ellipse",
                                  style="filled", fillcolor="lightgrey", **{"class": q("outcome")}))
        return name

    for outcome in node.get("outcomes") or ():
        outcome_node(outcome)
    outcome_set = set(outcome_nodes.values())
    row_of = make_rows(g, node, names, per_row)  # None: one rank a row
    seen: dict[str, int] = {}
    for tr in node.get("transitions") or ():
        src = names.get(tr["from"])
        if src is None:
            continue
        target = tr.get("to")
        if target is None:
            target = tr["outcome"]
        dst = names.get(target)
        if dst is None:
            dst = outcome_node(target)
            outcome_set.add(dst)
        eid = edge_id(path, tr["from"], tr["outcome"])
        n = seen.get(eid, 0)
        seen[eid] = n + 1
        if n:
            eid += ":%d" % (n + 1)
        titles[eid] = visible("%s: %s --%s--> %s" % (path, tr["from"], tr["outcome"], target))
        # External labels where rows are made: dot 2.43 corrupts its memory laying out labels of flat edges.
        attrs = {"id": q(eid), ("xlabel" if big or row_of is not None else "label"): q(tr["outcome"])}
        if dst in outcome_set:  # edges into outcomes do not rank: many long edges to one sink explode dot
            attrs["constraint"] = "false"
        elif row_of is not None and row_of[src] != row_of[dst]:  # from one row to another: neither ranks
            attrs.update(constraint="false", weight="0")  # nor pulls (the rows are made by the invisible edges)
        g.add_edge(pydot.Edge(src, dst, **attrs))
    if outcome_nodes:
        sink = pydot.Subgraph(rank="sink")
        for name in outcome_nodes.values():
            sink.add_node(pydot.Node(name))
        g.add_subgraph(sink)
    return g, titles


_dot = DotPool(min(os.cpu_count() or 1, 8))


def run_dot(graphs: list[pydot.Dot]) -> list[ET.Element]:
    """Lay out several graphs with one dot process; returns each one's <svg> element, in order."""
    try:
        docs = _dot.layout([g.to_string().encode() for g in graphs], DOT_TIMEOUT)
    except DotError as exc:
        raise GraphError(str(exc)) from exc
    return [ET.fromstring(doc) for doc in docs]


def run_dot_parallel(graphs: list[pydot.Dot]) -> list[ET.Element]:
    """``run_dot`` split over the kept dot processes (one per core): containers of one depth at once."""
    workers = min(_dot.size, len(graphs))
    if workers <= 1:
        return run_dot(graphs)
    chunks = [graphs[i::workers] for i in range(workers)]
    with concurrent.futures.ThreadPoolExecutor(workers) as pool:
        results = list(pool.map(run_dot, chunks))
    out: list[ET.Element] = [None] * len(graphs)  # type: ignore[list-item]
    for i, result in enumerate(results):
        out[i::workers] = result
    return out


def _size(svg: ET.Element) -> tuple[float, float]:
    box = svg.get("viewBox", "0 0 0 0").split()
    return float(box[2]), float(box[3])


def _bbox(g: ET.Element) -> tuple[float, float] | None:
    poly = g.find(_POLYGON)
    if poly is None:
        return None
    xs, ys = [], []
    for pair in poly.get("points", "").split():
        x, _, y = pair.partition(",")
        xs.append(float(x))
        ys.append(float(y))
    return (min(xs), min(ys)) if xs else None


class Renderer:
    """Cached, thread-safe rendering of structures to SVG."""

    def __init__(self, max_docs: int = 64, max_parts: int = 4096) -> None:
        self._lock = threading.Lock()
        self._docs: collections.OrderedDict[tuple, bytes] = collections.OrderedDict()
        self._parts: collections.OrderedDict[tuple, Part] = collections.OrderedDict()
        self._max_docs = max_docs
        self._max_parts = max_parts
        self.layouts = 0  # containers laid out by dot so far (for tests and benchmarks)

    def render(self, root: dict, key: str, expand: Iterable[str] | None = None, n_states: int | None = None) -> bytes:
        if n_states is None:
            n_states = structure.count(root)
        opened = open_set(root, expand, n_states)
        doc_key = (key, opened)
        with self._lock:
            doc = self._docs.get(doc_key)
            if doc is not None:
                self._docs.move_to_end(doc_key)
                return doc
            doc = self._render(root, key, opened, ROW_TRIALS if n_states <= AUTO_OPEN_LIMIT else 1)
            self._docs[doc_key] = doc
            while len(self._docs) > self._max_docs:
                self._docs.popitem(last=False)
            return doc

    def _part_key(self, key: str, node: dict, opened: frozenset[str]) -> tuple:
        prefix = node["path"] + "/"
        return (key, node["path"], frozenset(p for p in opened if p.startswith(prefix)))

    def _render(self, root: dict, key: str, opened: frozenset[str], trials: int) -> bytes:
        """The document; each container laid out in rows ``trials`` ways (row_options), the best kept."""
        by_depth: dict[int, list[dict]] = collections.defaultdict(list)
        for node, depth in structure.walk(root, lambda c: c["path"] in opened):
            if node["path"] in opened:
                by_depth[depth].append(node)
        done: dict[str, Part] = {}
        for depth in sorted(by_depth, reverse=True):
            todo = []
            for node in by_depth[depth]:
                pkey = self._part_key(key, node, opened)
                part = self._parts.get(pkey)
                if part is not None:
                    self._parts.move_to_end(pkey)
                    done[node["path"]] = part
                else:
                    todo.append((node, pkey))
            if not todo:
                continue
            built = []
            for node, _ in todo:
                sizes = {c["path"]: done[c["path"]][1:] for c in node.get("children") or () if c["path"] in done}
                built.append([build_dot(node, sizes, k) for k in row_options(node, sizes, trials)])
            drawn = iter(run_dot_parallel([g for ways in built for g, _ in ways]))
            self.layouts += len(todo)
            for (node, pkey), ways in zip(todo, built):
                svg, titles = max(((next(drawn), titles) for _, titles in ways), key=lambda d: fit_score(*_size(d[0])))
                part = self._compose(node, svg, done, titles)
                done[node["path"]] = part
                self._parts[pkey] = part
            while len(self._parts) > self._max_parts:
                self._parts.popitem(last=False)
        _, w, h = done[root["path"]]
        svg = ET.Element("{%s}svg" % SVG_NS, {"width": "%gpt" % w, "height": "%gpt" % h,
                                               "viewBox": "0 0 %g %g" % (w, h), "class": "fsm-graph"})
        svg.append(ET.Comment("fsmscope-child-0"))
        head, _, tail = ET.tostring(svg).partition(b"<!--fsmscope-child-0-->")
        out = [b'<?xml version="1.0" encoding="UTF-8"?>\n', head.replace(b"<svg ", b'<svg xmlns:xlink="%s" ' % XLINK_NS.encode(), 1)]
        _join(root["path"], done, out)
        out.append(tail)
        return b"".join(out)

    @staticmethod
    def _compose(node: dict, svg: ET.Element, done: dict[str, Part], titles: dict[str, str]) -> Part:
        """The container's drawing, its elements titled by ``titles``, with a hole in each open child's
        placeholder, serialized."""
        group = svg.find(_G)
        if group is None:
            raise GraphError("dot produced no graph for %s" % node["path"])
        for g in (group, *group.iter(_G)):
            title = g.find(_TITLE)
            eid = _PAGE.sub("", g.get("id", ""))
            if eid:
                g.set("id", eid)
            if title is not None and eid in titles:
                title.text = titles[eid]
        group.set("class", "cluster")
        frame = group.find(_POLYGON)
        if frame is not None:
            frame.set("class", "frame")
            frame.set("stroke", "#999999")
        placeholders = {state_id(c["path"]): c["path"] for c in node.get("children") or () if c["path"] in done}
        holes: list[str] = []
        for i, child in enumerate(list(group)):
            cpath = placeholders.get(child.get("id", ""))
            if child.tag != _G or cpath is None:
                continue
            corner = _bbox(child)
            if corner is None:
                continue
            wrapper = ET.Element(_G, {"transform": "translate(%g %g)" % corner})
            wrapper.append(ET.Comment("fsmscope-child-%d" % len(holes)))
            holes.append(cpath)
            group[i] = wrapper
        text = ET.tostring(group)
        start = text.index(b">")
        pieces: list[bytes | str] = _HOLE.split(_DECLARATIONS.sub(b"", text[:start]) + text[start:])
        for i in range(1, len(pieces), 2):
            pieces[i] = holes[int(pieces[i])]
        w, h = _size(svg)
        return pieces, w, h


def _join(path: str, done: dict[str, Part], out: list[bytes]) -> None:
    """Append the text of the drawing of ``path``, its open children's drawings in their holes."""
    for i, piece in enumerate(done[path][0]):
        if i % 2:
            _join(piece, done, out)  # type: ignore[arg-type]
        else:
            out.append(piece)  # type: ignore[arg-type]


_default = Renderer()


def render(root: dict, key: str, expand: Iterable[str] | None = None, n_states: int | None = None) -> bytes:
    """The SVG of a structure (``key`` identifies it, e.g. its hash) with the given containers open."""
    return _default.render(root, key, expand, n_states)
