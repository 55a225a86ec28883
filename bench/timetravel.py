"""Time-travel benchmarks (issue 9): seeking and paging a 1,000,000-event recorded run, a table against
the targets, each figure the median of 5 runs.

Server rows: GET .../status?seq= and GET .../history over HTTP (one kept-alive connection) to a real
uvicorn serving the run as a replay does (``History.from_log``: everything read from the recording,
through its .idx). Targets: the status at event 1,000,000 <= 50 ms; a page of 1,000 events <= 20 ms
at the start, the middle and the end of the run.

Timeline rows: GET .../timeline of the whole run (target <= 50 ms) and of one second of its middle,
from the machine's TimelineIndex built in one scan as ``fsmscope replay --serve`` builds it; and
what the index costs the machine: ``Feed.observe`` (the hub's work in the machine's thread) over
100,000 of the run's events with the index and with it switched off.

The log is written once by the real Recorder (bench/replay.py's ``generate``: a two-state loop);
``--log PATH`` keeps it there and reuses it on the next run. To add rows, append ``Row``s to what
``main`` measures (a row is a name, a target in seconds or None, and a function to time).

    .venv/bin/python bench/timetravel.py [--events N] [--log PATH]
"""

import argparse
import os
import shutil
import sys
import tempfile
from dataclasses import dataclass
from typing import Callable, Optional

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import httpx  # noqa: E402
from fsm.logfiles.log_reader import read_events  # noqa: E402
from fsm.observation.delivery import Batch  # noqa: E402
from replay import REPEATS, generate, median_time  # noqa: E402  (bench/replay.py's 1M-event recording)
import table  # noqa: E402
from table import verdict  # noqa: E402
from fsmscope.server.feed import Feed  # noqa: E402
from fsmscope.server.history import History  # noqa: E402
from fsmscope.server.log_history import LogHistory  # noqa: E402
from fsmscope.server.http_server import ServerThread  # noqa: E402
from fsmscope.server.timeline import TimelineIndex  # noqa: E402

BATCH = 256  # events per batch given to a feed
MACHINE = "loop"  # the name bench/replay.py's generate records under


@dataclass
class Row:
    name: str
    target: Optional[float]  # seconds; None: shown for information
    measure: Callable[[], None]


def print_table(title: str, rows: list[Row]) -> None:
    cells = []
    for row in rows:
        seconds = median_time(row.measure)
        target = "" if row.target is None else "<= %g ms" % (row.target * 1000)
        met = None if row.target is None else seconds <= row.target
        cells.append((row.name, target, "%.1f ms" % (seconds * 1000), verdict(met)))
    table.print_table(title, cells)


def serve(path: str) -> ServerThread:
    """A real server showing the recording as machine MACHINE, its history read from the log alone."""
    srv = ServerThread()
    first = next(read_events(path))
    srv.hub.ingest(first, "replay")
    srv.hub.get(MACHINE).read_past_from(LogHistory(path, MACHINE))
    return srv.start()


def getter(http: httpx.Client, url: str, **params: object) -> Callable[[], None]:
    def get() -> None:
        answer = http.get(url, params=params)
        answer.raise_for_status()
    return get


def server_rows(http: httpx.Client, path: str, last: int) -> list[Row]:
    status = "/api/machines/%s/status" % MACHINE
    history = "/api/machines/%s/history" % MACHINE
    target = min(1_000_000, last)
    t_target = History.from_log(path, MACHINE).page(since=target, limit=1)["events"][0]["t"]

    def first_question() -> None:  # a fresh log: its .idx is read on the way
        History.from_log(path, MACHINE).status_at(target)

    return [
        Row("status at event %d (?seq=)" % target, 0.050, getter(http, status, seq=target)),
        Row("status at the time of event %d (?t=)" % target, None, getter(http, status, t=t_target)),
        Row("status at event %d, a log just opened (in process)" % target, None, first_question),
        Row("page of 1,000 events at the start", 0.020, getter(http, history, since=1, limit=1000)),
        Row("page of 1,000 events in the middle", 0.020, getter(http, history, since=last // 2, limit=1000)),
        Row("page of 1,000 events at the end (order=desc)", 0.020, getter(http, history, limit=1000, order="desc")),
        Row("page of 1,000 events before the middle (order=desc)", None,
            getter(http, history, until=last // 2, limit=1000, order="desc")),
    ]


def observing(events: list[dict], indexed: bool) -> Callable[[], None]:
    """A feed given ``events`` in batches of ``BATCH``, as the delivery thread gives a busy machine's."""
    def observe() -> None:
        feed = Feed(MACHINE)
        if indexed:
            feed.add_sink(TimelineIndex().add_all)
        for start in range(0, len(events), BATCH):
            feed.take_batch(Batch(MACHINE, events[start:start + BATCH], None))
    return observe


def timeline_rows(http: httpx.Client, srv: ServerThread, path: str) -> list[Row]:
    index = TimelineIndex()
    events = []
    for event in read_events(path):
        index.add(event)
        if len(events) < 100_000 and event["kind"] != "snapshot":
            events.append(event)
    srv.hub.get(MACHINE).timeline = index
    url = "/api/machines/%s/timeline" % MACHINE
    span = index.answer(buckets=1)
    middle = (span["first"]["t"] + span["last"]["t"]) / 2
    return [
        Row("timeline of the whole run", 0.050, getter(http, url)),
        Row("timeline of 1 s in the middle, 10,000 buckets", None,
            getter(http, url, since_t=middle, until_t=middle + 1, buckets=10_000)),
        Row("Feed.take_batch of 100,000 events, timeline index on", None, observing(events, True)),
        Row("Feed.take_batch of 100,000 events, timeline index off", None, observing(events, False)),
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--events", type=int, default=1_050_000)
    parser.add_argument("--log", help="the recording to write once and reuse (default: a temporary file)")
    args = parser.parse_args()
    directory = None if args.log else tempfile.mkdtemp(prefix="fsmscope-bench-")
    path = args.log or os.path.join(directory, "loop.jsonl")
    if not os.path.exists(path):
        generate(path, args.events)
    srv = serve(path)
    try:
        http = httpx.Client(base_url=srv.base_url, headers={"Authorization": "Bearer " + srv.token}, timeout=30)
        span = History.from_log(path, MACHINE).span()
        http.get("/api/machines/%s/status" % MACHINE, params={"seq": 1}).raise_for_status()  # opens the log
        rows = server_rows(http, path, span["last_seq"]) + timeline_rows(http, srv, path)
        print_table("fsmscope time-travel benchmark: %d events (%.0f MB), median of %d"
                    % (span["last_seq"], os.path.getsize(path) / 1e6, REPEATS), rows)
    finally:
        srv.stop()
        if directory is not None:
            shutil.rmtree(directory)


if __name__ == "__main__":
    main()
