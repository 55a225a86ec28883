"""A newcomer's first view of a machine (issue 31 item 7), measured in real Chromium (Debian's) at
1440 x 900 and 1920 x 1080: how many of the states' and open containers' labels a new page shows
in its graph pane, clear of the minimap, and how big the smallest of them is on screen.

- the demo's pick-and-place machine (fsmscope/sim/task.py, 19 states, not run), a 31-state mission and a
  sequence of 30 steps (fsmscope/server/testing/mission.py): target every label shown, none under 9 px;
- a 600-state machine, running (fsmscope/server/testing/big_machine.py: semantic zoom): target its active
  state shown, no label shown under 9 px.

The machines are served by a real uvicorn on a free port (server.http_server). Run it under the
browser lock:

    flock /tmp/fsmscope-browser.lock .venv/bin/python bench/first_view_browser.py
"""

import os
import sys
import threading

# The repository first: run as a script, this folder comes first and its server.py would shadow the package.
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

import fsm  # noqa: E402
from fsmscope.server.http_server import ServerThread  # noqa: E402
from fsmscope.server.testing.big_machine import big_machine  # noqa: E402
from fsmscope.server.testing.browser import launch_chromium, open_page  # noqa: E402
from fsmscope.server.testing.mission import mission_machine, sequence_machine  # noqa: E402
from table import print_table, verdict  # noqa: E402

SCREENS = [(1440, 900), (1920, 1080)]
FLOOR_PX = 9.0

# Every state's and open container's label: shown (inside the graph pane, clear of the minimap when
# it is shown) or not, its size on screen; and whether the deepest active state is shown.
FIRST_VIEW = """() => {
  const pane = document.getElementById('graph').getBoundingClientRect();
  const mm = document.getElementById('minimap');
  const map = mm.hidden ? null : mm.getBoundingClientRect();
  const shown = (b) => b.left >= pane.left && b.right <= pane.right && b.top >= pane.top && b.bottom <= pane.bottom
    && !(map && b.right > map.left && b.left < map.right && b.bottom > map.top && b.top < map.bottom);
  const labels = [...document.querySelectorAll('#graph svg.fsm-graph :is(g.node.state, g.node.container, g.cluster) > text')]
    .map((t) => ({ shown: shown(t.getBoundingClientRect()), px: parseFloat(t.getAttribute('font-size')) * t.getScreenCTM().a }));
  const active = [...document.querySelectorAll('#graph g.node.active')].sort((a, b) => b.id.length - a.id.length)[0];
  return { labels, active: active ? shown(active.getBoundingClientRect()) : null };
}"""


def demo_machine():
    from fsmscope.sim.task import build_task_machine
    from fsmscope.sim.world import World

    return build_task_machine(World())


def first_view(browser, srv: ServerThread, name: str, size: tuple[int, int], ready: str) -> dict:
    """What a fresh page of ``name`` shows at ``size`` once ``ready`` (a selector) is, a second later."""
    page = open_page(browser, srv.url + "#m=" + name, *size, scene=False)
    try:
        page.wait_for_selector(ready)
        page.wait_for_timeout(1500)  # the marks, a fit made again on the active state, a semantic zoom
        return page.evaluate(FIRST_VIEW)
    finally:
        page.close()


def rows_of(name: str, view: dict, small: bool) -> tuple[str, str, str, str]:
    shown = [label["px"] for label in view["labels"] if label["shown"]]
    smallest = min(shown, default=0.0)
    measured = "%d of %d labels, smallest %.1f px" % (len(shown), len(view["labels"]), smallest)
    if small:
        return name, "all, >= 9 px", measured, verdict(len(shown) == len(view["labels"]) and smallest >= FLOOR_PX)
    measured += ", active state %s" % ("shown" if view["active"] else "not shown")
    return name, "active shown, >= 9 px", measured, verdict(bool(view["active"]) and smallest >= FLOOR_PX)


def main() -> None:
    from playwright.sync_api import sync_playwright

    fsm.set_loggers(*(lambda msg: None,) * 4)
    srv = ServerThread().start()
    gate = threading.Event()
    mission = mission_machine(gate)
    srv.hub.add_local(demo_machine(), name="demo")
    srv.hub.add_local(mission, name="mission")
    srv.hub.add_local(sequence_machine(30), name="sequence")
    big, stop = big_machine(3, 4, 14, tick=0.2)
    srv.hub.add_local(big, name="big")
    runners = [threading.Thread(target=mission.execute), threading.Thread(target=big.execute)]
    for runner in runners:
        runner.start()
    rows = []
    try:
        with sync_playwright() as p:
            browser = launch_chromium(p)
            for size in SCREENS:
                screen = "%dx%d" % size
                for name, label, ready in [("demo", "the demo (19 states)", "#graph svg.fsm-graph"),
                                           ("mission", "a 31-state mission", "#run-state.running"),
                                           ("sequence", "a sequence of 30 steps", "#graph svg.fsm-graph")]:
                    rows.append(rows_of("%s, %s" % (label, screen), first_view(browser, srv, name, size, ready), True))
                view = first_view(browser, srv, "big", size, "#run-state.running")
                rows.append(rows_of("600 states running, %s" % screen, view, False))
            browser.close()
    finally:
        gate.set()
        stop.set()
        for runner in runners:
            runner.join(10)
        srv.stop()
    print_table("A new page's first view of a machine", rows, measured="measured")


if __name__ == "__main__":
    main()
