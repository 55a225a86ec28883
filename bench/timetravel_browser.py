"""Time travel in the page (issue 9), measured in real Chromium (Debian's) against ``fsmscope replay LOG
--serve`` run as a user runs it, in its own process; a table against the targets:

- seek: a click on the timeline's time axis at a random point of a 1,000,000-event run, from the
  click's pointerdown to the end of the frame that paints the new instant (graph, tree, userdata and
  timeline): <= 100 ms, median and p95 of 20 instants; and to the later frame that adds the event log's
  window around the instant (for information);
- repaint: on a machine of 606 states drawn all open (6 containers of 10 containers of 9 states), the
  page's render of a new instant, from the start of its requestAnimationFrame callback to the end of
  that frame (style, layout and paint included; the timeline's canvas is drawn at the frame after):
  <= 16 ms, median of 50 instants;
- drag: the timeline's playhead dragged to and fro over a 100,000-event run for 3 s: frames a second
  the page draws (requestAnimationFrame callbacks) >= 30, and the distinct instants it showed.

A probe in the page wraps requestAnimationFrame: the app's callback named ``render`` is timed, and a
message it posts marks the end of its frame (a posted message runs once style, layout and paint are
done). The logs are written by the real Recorder (bench/replay.py's ``generate`` for the two-state
loop); ``--logs DIR`` keeps them there and reuses them. The pages are ones Playwright does not follow
(bench/quiet_page.py): it would have Chromium report it every request and websocket frame. Run it
under the browser lock:

    flock /tmp/fsmscope-browser.lock .venv/bin/python bench/timetravel_browser.py [--logs DIR]
"""

import argparse
import contextlib
import os
import random
import re
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from typing import Any, Iterator, Optional

# The repository first: run as a script, this folder comes first and its server.py would shadow the package.
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

import fsm  # noqa: E402
from fsm.logfiles.recorder import Recorder  # noqa: E402
from quiet_page import QuietPage  # noqa: E402
from replay import generate  # noqa: E402  (bench/replay.py: the two-state loop, recorded)
from fsmscope.server.testing.browser import launch_chromium  # noqa: E402
from fsmscope.server.testing.demo_process import FSMSCOPE  # noqa: E402
from fsmscope.server.testing.polling import wait_for  # noqa: E402
from table import print_table, verdict  # noqa: E402

SEEKS = 20  # instants of the 1M-event run
REPAINTS = 50  # instants of the 606-state run
DRAG_SECONDS = 3.0
DRAG_STEPS = 40  # pointer moves per sweep across the timeline
SETTLE = 0.3  # s after a seek: the event log's window around the instant loads 60 ms after it

# Installed in the page once it shows the machine (app.js calls requestAnimationFrame by its global name).
PROBE = """() => {
  const raf = window.requestAnimationFrame.bind(window);
  const probe = { input: null, renders: [] };
  window.__probe = probe;
  addEventListener("pointerdown", (e) => { probe.input = e.timeStamp; }, true);
  window.requestAnimationFrame = (callback) => raf((now) => {
    if (callback.name !== "render") return callback(now);
    const start = performance.now();
    callback(now);
    const scripted = performance.now() - start;
    const seq = window.fsmscope.instant.seq;
    const channel = new MessageChannel();
    channel.port1.onmessage = () => probe.renders.push({ start, scripted, end: performance.now(), seq });
    channel.port2.postMessage(null);
  });
  probe.count = () => {
    const c = probe.counter = { frames: 0, seqs: new Set(), gaps: [], last: null, on: true };
    const tick = (now) => {
      if (!c.on) return;
      c.frames += 1;
      c.seqs.add(window.fsmscope.instant.seq);
      if (c.last !== null) c.gaps.push(now - c.last);
      c.last = now;
      raf(tick);
    };
    raf(tick);
  };
  probe.stop = () => {
    const c = probe.counter;
    c.on = false;
    const seconds = c.gaps.reduce((a, b) => a + b, 0) / 1000;
    return { frames: c.frames, seconds, instants: c.seqs.size, worst: Math.max(...c.gaps) };
  };
}"""
# The nodes (states, outcomes) and open containers the graph draws.
DRAWN = "() => document.querySelectorAll('#graph g.node, #graph g.cluster').length"
# The renders since the click once the first of them is painted (the seek's: nothing else renders a paused replay).
AFTER_CLICK = """() => {
  const probe = window.__probe;
  const since = probe.input === null ? [] : probe.renders.filter((r) => r.start > probe.input);
  return since.length ? since : null;
}"""


@contextlib.contextmanager
def served(arguments: list[str], says: str) -> Iterator[tuple[str, subprocess.Popen]]:
    """``fsmscope ARGUMENTS`` in its own process: yields (the address it says on stderr once it serves, found
    by the pattern ``says``, and the process); Ctrl-C ends it if it has not ended by itself."""
    # Ctrl-C (SIGINT) ends it even when this runs in the background, where a shell ignores SIGINT.
    proc = subprocess.Popen(FSMSCOPE + arguments, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))

    def address() -> Optional[re.Match]:
        line = proc.stderr.readline()
        if not line:
            raise RuntimeError("fsmscope %s ended (exit %s) before serving" % (arguments[0], proc.wait()))
        return re.search(says, line)

    try:
        found = wait_for(address, 600, interval=0, what="fsmscope %s to say its address" % arguments[0])
        threading.Thread(target=proc.stderr.read, daemon=True).start()  # whatever it says later
        yield found.group(1), proc
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGINT)
        proc.wait(30)


@contextlib.contextmanager
def dashboard(log: str) -> Iterator[QuietPage]:
    """A Chromium page showing the replay of ``log``, paused at its start, the probe installed."""
    from playwright.sync_api import sync_playwright

    with served(["replay", log, "--serve"], r"replaying \S+ at (http://\S+)") as (url, _), sync_playwright() as pw:
        browser = launch_chromium(pw)
        try:
            with page_of(browser, url) as page:
                page.wait_for("() => window.fsmscope.instant.seq !== null")
                page.evaluate(PROBE)
                yield page
        finally:
            browser.close()


@contextlib.contextmanager
def page_of(browser: Any, url: str) -> Iterator[QuietPage]:
    """A new page of ``browser`` showing the dashboard at ``url`` with its graph and timeline; closed after,
    and failing if the page met an uncaught error."""
    page = QuietPage(browser, url)
    try:
        page.wait_for_selector("#graph svg")
        page.wait_for_selector("#timeline canvas")
        yield page
        if page.errors:
            raise RuntimeError("the page failed: %s" % page.errors)
    finally:
        page.close()


def axis(page: QuietPage) -> tuple[float, float, float]:
    """(x of the run's start, x of its end, y) on the timeline's time axis, in page pixels."""
    layout = page.evaluate("async () => (await import('/timeline_draw.js')).LAYOUT")
    box = page.bounding_box("#timeline canvas")
    return box["x"] + layout["labelW"] + 1, box["x"] + box["width"] - layout["padR"] - 1, box["y"] + layout["axisH"] / 2


def seek_randomly(page: QuietPage, rng: random.Random) -> dict:
    """Click random points of the time axis until one shows another instant: the click's time (``input``),
    the probe's record of the render that showed the instant (``shown``) and of the next one, which adds
    the event log's window around it (``log``, or None)."""
    x0, x1, y = axis(page)
    while True:
        before = page.evaluate("() => window.fsmscope.instant.seq")
        page.evaluate("() => { window.__probe.renders = []; window.__probe.input = null; }")
        page.click(rng.uniform(x0, x1), y)
        page.wait_for(AFTER_CLICK)
        time.sleep(SETTLE)
        renders = page.evaluate(AFTER_CLICK)
        if renders[0]["seq"] != before:
            return {"input": page.evaluate("() => window.__probe.input"), "shown": renders[0],
                    "log": renders[1] if len(renders) > 1 else None}


def frame(render: dict) -> float:
    """ms from the start of a render to the end of its frame."""
    return render["end"] - render["start"]


def p95(values: list[float]) -> float:
    return statistics.quantiles(values, n=20, method="inclusive")[-1]


def seek_rows(log: str, rng: random.Random) -> list[tuple[str, str, str, str]]:
    with dashboard(log) as page:
        seek_randomly(page, rng)  # the first seek warms the server's log reader and the page's code
        seeks = [seek_randomly(page, rng) for _ in range(SEEKS)]
    times = [s["shown"]["end"] - s["input"] for s in seeks]
    logged = [s["log"]["end"] - s["input"] for s in seeks if s["log"]]
    median = statistics.median(times)
    return [("seek a 1,000,000-event run: click on the time axis to the painted frame (%d instants)" % SEEKS,
             "<= 100 ms", "%.1f ms (p95 %.1f)" % (median, p95(times)), verdict(median <= 100)),
            ("  to the frame that adds the event log around the instant", "",
             "%.1f ms (p95 %.1f)" % (statistics.median(logged), p95(logged)), "")]


def repaint_rows(log: str, rng: random.Random) -> list[tuple[str, str, str, str]]:
    with dashboard(log) as page:
        deepest = page.evaluate("() => [...document.querySelector('#depth').options].filter((o) => !o.hidden)"
                                ".pop().value")
        page.select_option("#depth", deepest)
        page.wait_for("() => (%s)() >= 600" % DRAWN)
        drawn = page.evaluate(DRAWN)
        seek_randomly(page, rng)
        seeks = [seek_randomly(page, rng) for _ in range(REPAINTS)]
    framed = statistics.median(frame(s["shown"]) for s in seeks)
    scripted = statistics.median(s["shown"]["scripted"] for s in seeks)
    logged = [frame(s["log"]) for s in seeks if s["log"]]
    return [("repaint an instant, 606 states (%d graph elements) drawn: render to painted frame" % drawn,
             "<= 16 ms", "%.1f ms" % framed, verdict(framed <= 16)),
            ("  of which the render's script (graph, tree, userdata, the timeline's text; its canvas draws at "
             "the next frame)", "", "%.1f ms" % scripted, ""),
            ("  then the event log's window around the instant, render to painted frame", "",
             "%.1f ms" % statistics.median(logged), "")]


def drag_row(log: str) -> tuple[str, str, str, str]:
    with dashboard(log) as page:
        x0, x1, y = axis(page)
        page.mouse_move(x0, y)
        page.mouse_down()
        page.evaluate("() => window.__probe.count()")
        end, forward = time.monotonic() + DRAG_SECONDS, True
        while time.monotonic() < end:
            page.mouse_move(x1 if forward else x0, y, steps=DRAG_STEPS)
            forward = not forward
        page.mouse_up()
        drag = page.evaluate("() => window.__probe.stop()")
    rate = drag["frames"] / drag["seconds"]
    return ("drag the playhead over a 100,000-event run for %.0f s" % DRAG_SECONDS, ">= 30 frames/s",
            "%.0f frames/s, %d instants shown, longest frame %.0f ms" % (rate, drag["instants"], drag["worst"]),
            verdict(rate >= 30))


def nested_machine() -> Any:
    """606 states: 6 containers of 10 containers of 9 states, each state 'succeeded' into the next."""
    def chain(outcomes: list[str], children: list[tuple[str, Any]]) -> Any:
        sm = fsm.StateMachine(outcomes=outcomes)
        with sm:
            for i, (label, state) in enumerate(children):
                after = children[i + 1][0] if i + 1 < len(children) else "succeeded"
                fsm.StateMachine.add(label, state, transitions={"succeeded": after})
        return sm

    def leaf() -> Any:
        return fsm.CBState(lambda ud: "succeeded", outcomes=["succeeded"])

    return chain(["succeeded"], [("PART%d" % i, chain(["succeeded"], [
        ("STEP%d" % j, chain(["succeeded"], [("S%d" % k, leaf()) for k in range(9)])) for j in range(10)]))
        for i in range(6)])


def record_nested(path: str, runs: int = 3) -> None:
    sm = nested_machine()
    with Recorder(path) as recorder:
        fsm.attach(sm, recorder, name="nested")
        for _ in range(runs):
            sm.execute()


def logs(directory: str) -> dict[str, str]:
    """The three recordings, written unless ``directory`` has them already."""
    paths = {name: os.path.join(directory, name + ".jsonl") for name in ("loop-1m", "loop-100k", "nested-606")}
    if not os.path.exists(paths["loop-1m"]):
        generate(paths["loop-1m"], 1_050_000)
    if not os.path.exists(paths["loop-100k"]):
        generate(paths["loop-100k"], 100_000)
    if not os.path.exists(paths["nested-606"]):
        record_nested(paths["nested-606"])
    return paths


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--logs", help="where to write the recordings once and reuse them (default: a temporary "
                                       "folder)")
    parser.add_argument("--seed", type=int, default=9)
    args = parser.parse_args()
    directory = args.logs or tempfile.mkdtemp(prefix="fsmscope-bench-")
    os.makedirs(directory, exist_ok=True)
    rng = random.Random(args.seed)
    try:
        paths = logs(directory)
        rows = [*seek_rows(paths["loop-1m"], rng), *repaint_rows(paths["nested-606"], rng),
                drag_row(paths["loop-100k"])]
    finally:
        if not args.logs:
            shutil.rmtree(directory)
    print_table("fsmscope time travel in Chromium (%d cores), measured in the page" % os.cpu_count(), rows,
                measured="measured")


if __name__ == "__main__":
    main()
