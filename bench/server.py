"""Server benchmarks (medians): event-to-browser latency, per-request HTTP latency, fan-out throughput
against a bare `websockets` server, a machine's transition rate with a stalled client, and the server's
memory during the stall.

    .venv/bin/python bench/server.py [--repeat 3] [--stall-seconds 60]

Clients run in a separate process (so they do not share the server's GIL); latency is the client's
``time.time()`` on receipt minus the event's ``t`` (same host clock).
Targets: p99 < 5 ms at 1,000 events/s to 10 clients; p50 < 2 ms per GET on one kept-alive connection; >= 0.8 of the bare server's events/s per client with
50 clients; <= 5 % fewer transitions/s with one stalled client; memory bounded during a stall.
"""

import argparse
import asyncio
import json
import multiprocessing as mp
import os
import resource
import statistics
import sys
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

import fsm  # noqa: E402
from fsm.observation.encoding import dumps  # noqa: E402
from fsm.observation.schema import build  # noqa: E402
from fsmscope.server.http_server import ServerThread  # noqa: E402
from fsmscope.server.testing.clients import stalled_stream  # noqa: E402  (the stalled browser of the tests)


def rss_mb():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


# Clients (in a child process).

def _clients(url, n, expect, out, ready):
    async def one(i):
        from websockets.asyncio.client import connect
        lat, count, first, last = [], 0, None, None
        async with connect(url, compression=None, max_size=None) as ws:
            ready.put(i)
            while True:
                try:
                    frame = json.loads(await asyncio.wait_for(ws.recv(), 3))
                except asyncio.TimeoutError:
                    break
                now = time.time()
                if frame.get("type") == "events":
                    evs = frame["events"]
                elif frame.get("kind"):  # the bare server sends events as they are
                    evs = [frame]
                else:
                    continue
                for ev in evs:
                    if ev.get("kind") != "log":
                        continue
                    if ev["msg"] == "end":
                        return lat, count, first, last
                    if first is None:
                        first = now
                    last = now
                    count += 1
                    lat.append(now - ev["t"])
        return lat, count, first, last

    async def main():
        return await asyncio.gather(*(one(i) for i in range(n)))
    out.put(asyncio.run(main()))


def run_clients(url, n, expect):
    ctx = mp.get_context("spawn")
    out, ready = ctx.Queue(), ctx.Queue()
    proc = ctx.Process(target=_clients, args=(url, n, expect, out, ready), daemon=True)
    proc.start()
    for _ in range(n):
        ready.get(timeout=30)
    return proc, out


def emit_paced(rep, path, n, rate):
    """Emit n log events through the machine's reporter at ``rate``/s (rate 0: as fast as possible)."""
    start = time.perf_counter()
    for i in range(n):
        if rate:  # sleep (releasing the GIL, as a machine waiting on the world does) until the event is due
            delay = start + i / rate - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
        rep.send(build.log, path, "info", "tick %d" % i)
    rep.send(build.log, path, "info", "end")


def make_machine():
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": "done"})
    return sm


def fsmscope_run(n_clients, n_events, rate):
    srv = ServerThread().start()
    entry = srv.hub.add_local(make_machine(), name="bench")
    url = "ws://127.0.0.1:%d/api/machines/bench/stream?token=%s" % (srv.port, srv.token)
    proc, out = run_clients(url, n_clients, n_events)
    time.sleep(0.3)
    emit_paced(entry.local.reporter, "/SM_ROOT", n_events, rate)
    results = out.get(timeout=120)
    proc.join(10)
    srv.stop()
    return results


def bare_run(n_clients, n_events, rate):
    """The same events, hand-off and fan-out on a bare `websockets` server: one frame per event per client."""
    from websockets.asyncio.server import broadcast, serve

    clients = set()
    state = {}
    started = threading.Event()

    async def handler(ws):
        clients.add(ws)
        try:
            await ws.wait_closed()
        finally:
            clients.discard(ws)

    async def main():
        state["loop"] = asyncio.get_running_loop()
        state["stop"] = asyncio.Event()
        async with serve(handler, "127.0.0.1", 0, compression=None) as server:
            state["port"] = server.sockets[0].getsockname()[1]
            started.set()
            await state["stop"].wait()

    thread = threading.Thread(target=lambda: asyncio.run(main()), daemon=True)
    thread.start()
    started.wait(10)
    loop = state["loop"]
    sm = make_machine()
    buf = []

    def drain():
        while buf:
            broadcast(clients, dumps(buf.pop(0)).decode())

    rep = fsm.attach(sm, lambda ev: (buf.append(ev), loop.call_soon_threadsafe(drain)), name="bare")
    proc, out = run_clients("ws://127.0.0.1:%d/" % state["port"], n_clients, n_events)
    time.sleep(0.3)
    emit_paced(rep, "/SM_ROOT", n_events, rate)
    results = out.get(timeout=120)
    proc.join(10)
    loop.call_soon_threadsafe(state["stop"].set)
    thread.join(5)
    return results


def pct(values, p):
    values = sorted(values)
    return values[min(len(values) - 1, int(p / 100 * len(values)))]


def rate_per_client(results):
    return [count / (last - first) for _, count, first, last in results if last and last > first]


# Transition rate with a stalled client.

def loop_machine(n):
    counter = [0]

    def step(ud):
        counter[0] += 1
        return "again" if counter[0] < n else "stop"
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(step, outcomes=["again", "stop"]), {"again": "B", "stop": "done"})
        fsm.StateMachine.add("B", fsm.CBState(lambda ud: "go", outcomes=["go"]), {"go": "A"})
    return sm, counter


def _reader(url, ready):
    """A healthy client: reads every frame until the stream has been quiet for 3 s."""
    async def main():
        from websockets.asyncio.client import connect
        async with connect(url, compression=None, max_size=None) as ws:
            ready.put(1)
            while True:
                try:
                    await asyncio.wait_for(ws.recv(), 3)
                except (asyncio.TimeoutError, Exception):
                    return
    asyncio.run(main())


def transition_rate(client, n=100_000):
    """Transitions/s of a two-state loop served by a hub, with ``client`` = none, healthy or stalled.

    Loggers are off (as the runtime's reference numbers were taken): printing every transition
    would cost more than the hub and hide it.
    """
    srv = ServerThread().start()
    sm, counter = loop_machine(n)
    srv.hub.add_local(sm, name="loop")
    raw = proc = None
    if client == "stalled":
        raw = stalled_stream(srv, "loop")
    elif client == "healthy":
        ctx = mp.get_context("spawn")
        ready = ctx.Queue()
        url = "ws://127.0.0.1:%d/api/machines/loop/stream?token=%s" % (srv.port, srv.token)
        proc = ctx.Process(target=_reader, args=(url, ready), daemon=True)
        proc.start()
        ready.get(timeout=30)
    time.sleep(0.2)
    t = time.perf_counter()
    sm.execute()
    elapsed = time.perf_counter() - t
    if raw is not None:
        raw.close()
    if proc is not None:
        proc.terminate()
        proc.join(5)
    srv.stop()
    return counter[0] * 2 / elapsed


def stall_memory(seconds):
    """A machine looping with a paced sleep-free workload for ``seconds`` while a client never reads."""
    srv = ServerThread().start()
    stop = threading.Event()

    def step(ud):
        ud.blob = "x" * 500
        time.sleep(0.0002)
        return "stop" if stop.is_set() else "again"
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(step, outcomes=["again", "stop"], output_keys=["blob"]),
                             {"again": "A", "stop": "done"})
    entry = srv.hub.add_local(sm, name="stall")
    raw = stalled_stream(srv, "stall")
    thread = threading.Thread(target=sm.execute, daemon=True)
    before = rss_mb()
    thread.start()
    samples = []
    for _ in range(int(seconds)):
        time.sleep(1)
        samples.append(rss_mb())
    stop.set()
    thread.join(10)
    events = entry.local.reporter.last_seq
    clients = len(entry.feed.clients)
    raw.close()
    srv.stop()
    return before, samples, events, clients


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--stall-seconds", type=float, default=60)
    parser.add_argument("--only", choices=["latency", "http", "fanout", "rate", "memory"], action="append",
                        help="run only these tables (repeatable; default: all)")
    args = parser.parse_args()
    only = set(args.only or ["latency", "http", "fanout", "rate", "memory"])
    print("fsmscope server benchmarks, median of %d runs, cores=%d\n" % (args.repeat, os.cpu_count()))

    if "latency" in only:
        latency_table(args.repeat)
    if "http" in only:
        http_table(args.repeat)
    if "fanout" in only:
        fanout_table(args.repeat)
    if "rate" in only:
        rate_table(args.repeat)
    if "memory" in only:
        memory_table(args.stall_seconds)


def latency_table(repeat):
    p50s, p99s, maxs = [], [], []
    for _ in range(repeat):
        results = fsmscope_run(10, 3000, 1000)
        lat = [x for r in results for x in r[0]]
        p50s.append(pct(lat, 50) * 1000)
        p99s.append(pct(lat, 99) * 1000)
        maxs.append(max(lat) * 1000)
    print("| event-to-client latency, 1,000 events/s, 10 clients | p50 ms | p99 ms | max ms | target |")
    print("|---|---|---|---|---|")
    print("| fsmscope | %.2f | %.2f | %.2f | p99 < 5 ms: %s |\n" % (statistics.median(p50s), statistics.median(p99s),
                                                             statistics.median(maxs),
                                                             "met" if statistics.median(p99s) < 5 else "MISSED"))


def request_times(n=200):
    """Seconds per GET /api/health, ``n`` sent one after another on one kept-alive connection."""
    import httpx

    srv = ServerThread().start()
    times = []
    with httpx.Client(base_url=srv.base_url, headers={"Authorization": "Bearer " + srv.token}, timeout=5) as http:
        http.get("/api/health")  # connect outside the timing
        for _ in range(n):
            start = time.perf_counter()
            http.get("/api/health")
            times.append(time.perf_counter() - start)
    srv.stop()
    return times


def http_table(repeat):
    p50s, p99s = [], []
    for _ in range(max(repeat, 5)):
        times = request_times()
        p50s.append(pct(times, 50) * 1000)
        p99s.append(pct(times, 99) * 1000)
    p50 = statistics.median(p50s)
    print("| per-request latency on one kept-alive connection, 200 sequential GET /api/health, median of %d "
          "| p50 ms | p99 ms | target |" % len(p50s))
    print("|---|---|---|---|")
    print("| fsmscope | %.2f | %.2f | p50 < 2 ms: %s |\n" % (p50, statistics.median(p99s), "met" if p50 < 2 else "MISSED"))


def fanout_table(repeat):
    ours, bare = [], []
    for _ in range(repeat):
        ours.append(statistics.median(rate_per_client(fsmscope_run(50, 15000, 5000))))
        bare.append(statistics.median(rate_per_client(bare_run(50, 15000, 5000))))
    ratio = statistics.median(ours) / statistics.median(bare)
    print("| fan-out, 15,000 events at 5,000/s, 50 clients | events/s per client (median) | ratio |")
    print("|---|---|---|")
    print("| bare websockets server (one frame per event, broadcast) | %.0f | 1.00 |" % statistics.median(bare))
    print("| fsmscope (FastAPI + uvicorn, batched under load) | %.0f | %.2f (target >= 0.8: %s) |\n"
          % (statistics.median(ours), ratio, "met" if ratio >= 0.8 else "MISSED"))



def rate_table(repeat):
    quiet = lambda msg: None  # noqa: E731
    fsm.set_loggers(quiet, quiet, quiet, quiet)
    rates = {"none": [], "healthy": [], "stalled": []}
    for _ in range(max(repeat, 5)):  # interleaved, so a noisy neighbour hits every kind alike
        for kind in rates:
            rates[kind].append(transition_rate(kind))
    med = {kind: statistics.median(v) for kind, v in rates.items()}
    stall_drop = 1 - med["stalled"] / med["none"]
    print("| machine transitions/s (two-state loop, hub attached, loggers off), median of %d | transitions/s "
          "| vs no client | vs one healthy client |" % len(rates["none"]))
    print("|---|---|---|---|")
    print("| no client | %.0f | | |" % med["none"])
    print("| one healthy client (reads every frame) | %.0f | %+.1f %% | |"
          % (med["healthy"], (med["healthy"] / med["none"] - 1) * 100))
    print("| one stalled client (never reads) | %.0f | %+.1f %% (target >= -5 %%: %s) | %+.1f %% |\n"
          % (med["stalled"], -stall_drop * 100, "met" if stall_drop <= 0.05 else "MISSED",
             (med["stalled"] / med["healthy"] - 1) * 100))



def memory_table(stall_seconds):
    before, samples, events, clients = stall_memory(stall_seconds)
    print("| stalled client for %.0f s (machine emitting ~%.0f events/s) | RSS MB |" % (stall_seconds,
                                                                                    events / stall_seconds))
    print("|---|---|")
    print("| before | %.1f |" % before)
    for s in sorted({min(len(samples) - 1, k) for k in (0, 9, 29, len(samples) - 1)}):
        print("| after %d s | %.1f |" % (s + 1, samples[s]))
    print("| stalled client still connected at the end | %s |" % ("yes" if clients else "no (evicted)"))


if __name__ == "__main__":
    main()
