"""``fsmscope export LOG --html OUT.html``: a recorded run as one HTML file that opens from disk
(file://) with no server and no network, and shows the run as the dashboard shows ``fsmscope
replay LOG --serve``: graph, timeline, hierarchy, userdata and its diffs, event log, playhead.

The page is fsmscope/static/index.html with its stylesheets inlined and its ES modules embedded as data:
URLs in an import map (a module script cannot be loaded by URL from file://): each module's
relative imports become bare ``fsmscope/...`` specifiers that the map resolves, and the two
modules that talk to a server (api.js, stream.js) are swapped for fsmscope/static/offline/'s, which answer
the same questions from the recording embedded as JSON: its events, keyframes (statuses rebuilt by
fsm's own reducer every KEYFRAME_EVERY events), the whole run's timeline (fsmscope/server/timeline.py) and
the graph drawings (fsmscope/server/graph.py) the depth menu offers and the state statistics
(fsm/logfiles/summary.py) of the whole recording. Nothing user-provided is ever HTML:
the JSON is escaped so that no text in it can end its script element.
"""

from __future__ import annotations

import base64
import hashlib
import html
import os
import posixpath
import re
from typing import Callable, Iterable

import orjson

from fsm.logfiles.log_reader import Problem, read_events
from fsm.logfiles.summary import Summary
from fsm.observation import structure
from fsm.observation.status import Status

from . import graph
from .hub import structure_hash
from .static_files import static_dir
from .timeline import TimelineIndex

MAX_MB = 64  # default size limit of a log: the whole run goes into the page, which a browser must hold
KEYFRAME_EVERY = 1000  # events between two embedded statuses (a seek applies at most this many)
TIMELINE_BUCKETS = 4000  # bands per container of the embedded whole-run timeline (zooming slices it)
SPECIFIER = "fsmscope/"
SERVER_MODULES = {"api.js": "offline/api.js", "stream.js": "offline/stream.js"}  # replaced in the file
OFFLINE_STYLE = "offline/offline.css"
DATA_ID = "fsmscope-export"

_IMPORT = re.compile(r"""(\b(?:from|import)\s*)(["'])(\.\.?/[^"']+)\2""")
_STYLESHEET = re.compile(r'<link rel="stylesheet" href="([^"]+)">')
_MODULE = re.compile(r'<script type="module" src="([^"]+)"></script>')
_PRELOAD = re.compile(r'<link rel="modulepreload" href="[^"]+">\n')  # the export embeds every module
_FLEET_LINK = re.compile(r'\s*<a class="fleet-link"[^>]*>[^<]*</a>')  # the server's fleet page: a file has none


class ExportError(Exception):
    """The log cannot be exported (too big, no events, no dashboard files); the message says why."""


def export_html(log: str, max_bytes: int = MAX_MB << 20, on_problem: Callable[[Problem], None] | None = None) -> str:
    """The page of the run recorded in ``log``; ``on_problem`` hears of each line skipped."""
    size = os.path.getsize(log) if os.path.isfile(log) else 0
    if size > max_bytes:
        raise ExportError("%s is %.1f MB, above the limit of %.1f MB: the whole run goes into one page "
                          "(raise it with --max-mb)" % (log, size / 2**20, max_bytes / 2**20))
    machines = recorded_machines(read_events(log, on_problem))
    if not machines:
        raise ExportError("%s: no events" % log)
    return page({"log": os.path.basename(log), "machines": machines}, "fsmscope: " + os.path.basename(log))


def recorded_machines(events: Iterable[dict]) -> list[dict]:
    """What the page needs of each machine of a log, in the order they first appear."""
    by_machine: dict[str, list[dict]] = {}
    for event in events:
        by_machine.setdefault(event["machine"], []).append(event)
    out = [recorded_machine(name, evs) for name, evs in by_machine.items()]
    return [m for m in out if m["events"]]


def _keyframe(status: Status) -> dict:
    """A status as GET .../status?seq= answers it (without the structure)."""
    data = status.to_dict()
    data.pop("structure")
    return data


def recorded_machine(name: str, events: list[dict]) -> dict:
    """One machine's events (snapshots left out: they are not events of the run), keyframes
    ``[events applied, status]``, its status at the end, timeline and graph drawings.
    A snapshot ahead of the events (lines lost before it) is applied as fsm.logfiles.log_reader.seek does."""
    status = Status(name)
    timeline = TimelineIndex()
    kept: list[dict] = []
    keyframes = [[0, _keyframe(status)]]
    summary = Summary()
    for event in events:
        summary.add(event)
        if event["kind"] == "snapshot":
            if event["seq"] > status.last_seq:
                status.apply(event)
                keyframes.append([len(kept), _keyframe(status)])
            continue
        status.apply(event)
        timeline.add(event)
        kept.append(event)
        if len(kept) % KEYFRAME_EVERY == 0:
            keyframes.append([len(kept), _keyframe(status)])
    end = status.to_dict()
    return {"name": name, "events": kept, "keyframes": keyframes, "end": end,
            "timeline": timeline.answer(buckets=TIMELINE_BUCKETS), "graphs": drawings(end["structure"]),
            "stats": state_stats(summary, name, kept)}


def state_stats(summary: Summary, name: str, kept: list[dict]) -> dict:
    """The whole recording's state statistics in GET /summary's shape (fsmscope/server/state_stats.py), every
    state visited, and ``unvisited``: what a state never entered has."""
    seen = summary.machines.get(name)
    last = kept[-1]["seq"] if kept else None
    return {"counted": {"first_seq": kept[0]["seq"] if kept else None, "last_seq": last}, "last_seq": last,
            "complete": True, "states": {p: summary.state(name, p) for p in (seen.visits if seen else ())},
            "unvisited": summary.state(name, "")}


def depth_of(path: str, root_path: str) -> int:
    """A container's level below the root (0), as fsmscope/static/depth.js counts it."""
    return 0 if path == root_path else len(path[len(root_path):].split("/")) - 1


def drawings(root: dict | None) -> list[list]:
    """``[expand, svg]`` for the graph's default (expand null) and each level the depth menu offers."""
    if root is None:
        return []
    key, n_states = structure_hash(root), structure.count(root)
    paths = [c["path"] for c in structure.containers(root)]
    deepest = max(depth_of(p, root["path"]) for p in paths) + 1
    sets: list[list[str] | None] = [None]
    sets += [sorted(p for p in paths if depth_of(p, root["path"]) < d) for d in range(1, deepest + 1)]
    try:
        return [[expand, graph.render(root, key, expand, n_states).decode()] for expand in sets]
    except graph.GraphError as exc:
        raise ExportError("cannot draw the graph: %s" % exc) from None


def _data_url(text: str, media_type: str = "text/javascript") -> str:
    return "data:%s;charset=utf-8;base64,%s" % (media_type, base64.b64encode(text.encode()).decode())


def import_map(root: str, entry: str) -> dict[str, str]:
    """Every module the page reaches from ``entry`` (a path in ``root``), as a data: URL under its bare
    specifier, with its relative imports rewritten to bare ones (and api.js, stream.js swapped for
    the offline ones, except in the offline modules themselves)."""
    imports: dict[str, str] = {}
    todo = [entry]
    while todo:
        path = todo.pop()
        if SPECIFIER + path in imports:
            continue

        def rewrite(found: re.Match) -> str:
            target = posixpath.normpath(posixpath.join(posixpath.dirname(path), found.group(3)))
            if not path.startswith("offline/"):
                target = SERVER_MODULES.get(target, target)
            if target.startswith("../"):
                raise ExportError("static/%s imports %s, outside the dashboard's files" % (path, found.group(3)))
            todo.append(target)
            return found.group(1) + found.group(2) + SPECIFIER + target + found.group(2)

        with open(os.path.join(root, path), encoding="utf-8") as handle:
            imports[SPECIFIER + path] = _data_url(_IMPORT.sub(rewrite, handle.read()))
    return imports


def _hash(text: str) -> str:
    return "'sha256-%s'" % base64.b64encode(hashlib.sha256(text.encode()).digest()).decode()


def _script_json(data: object) -> str:
    """JSON to put inside a <script> element: no '<' at all, so no text in it can close the element."""
    return (orjson.dumps(data).decode()
            .replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026"))


def _substitute(pattern: re.Pattern, replace: Callable[[re.Match], str], text: str, what: str) -> str:
    out, n = pattern.subn(replace, text)
    if not n:
        raise ExportError("fsmscope/static/index.html has no %s" % what)
    return out


def page(data: dict, title: str) -> str:
    """fsmscope/static/index.html made self-contained, carrying ``data`` (read by fsmscope/static/offline/recording.js)."""
    root = static_dir()
    if root is None or not os.path.isfile(os.path.join(root, "index.html")):
        raise ExportError("the dashboard's files (the static package) are not installed")

    def read(path: str) -> str:
        with open(os.path.join(root, path), encoding="utf-8") as handle:
            return handle.read()

    styles: list[str] = []

    def inline_style(found: re.Match) -> str:
        styles.append(read(found.group(1)))
        return "<style>%s</style>" % styles[-1]

    text = _substitute(_STYLESHEET, inline_style, read("index.html"), "stylesheet link")
    styles.append(read(OFFLINE_STYLE))
    text = text.replace("</head>", "<style>%s</style>\n</head>" % styles[-1], 1)
    text = _PRELOAD.sub("", text)
    text = _substitute(_FLEET_LINK, lambda m: "", text, "fleet link")
    module = _MODULE.search(text)
    if module is None:
        raise ExportError("fsmscope/static/index.html has no module script")
    entry = module.group(1)
    scripts = [orjson.dumps({"imports": import_map(root, entry)}).decode(), 'import "%s%s";' % (SPECIFIER, entry)]
    text = (text[:module.start()] + '<script type="importmap">%s</script>\n<script type="module">%s</script>'
            % tuple(scripts) + text[module.end():])
    if any("</style" in s.lower() for s in styles) or any("</script" in s.lower() for s in scripts):
        raise ExportError("a stylesheet or the import map would end its element early")
    policy = ("default-src 'none'; script-src %s data:; style-src %s; img-src data:; base-uri 'none'; "
              "form-action 'none'" % (" ".join(map(_hash, scripts)), " ".join(map(_hash, styles))))
    text = _substitute(re.compile(r'<meta charset="utf-8">'), lambda m: m.group(0) +
                       '\n<meta http-equiv="Content-Security-Policy" content="%s">' % policy, text, "charset")
    text = _substitute(re.compile(r"<title>[^<]*</title>"), lambda m: "<title>%s</title>" % html.escape(title),
                       text, "title")
    body = '<script type="application/json" id="%s">%s</script>\n</body>' % (DATA_ID, _script_json(data))
    return _substitute(re.compile("</body>"), lambda m: body, text, "body")
