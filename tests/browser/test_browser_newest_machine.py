"""A script that builds a new machine per loop, run by a real ``fsmscope run``: the page follows the
newest machine of the script (``loop``, ``loop-2``, ``loop-3``...) unless the user chose the one shown,
in the list or by the address the page was opened at. Real Chromium at 1440x900."""

from __future__ import annotations

import contextlib
import os
import queue
import re
import subprocess
import sys
import threading

from browser_support import ROOT
from fsmscope.server.testing.browser import open_page
from fsmscope.server.testing.polling import wait_for

# Machine N waits in WAIT until the file goN exists in the working directory, then ends: a new one is built.
SCRIPT = """
import os, time
import fsm

def wait_for(name):
    def cb(ud):
        while not os.path.exists(name):
            time.sleep(0.02)
        return "done"
    return cb

for n in range(1, 4):
    sm = fsm.StateMachine(outcomes=["done"])
    with sm:
        fsm.StateMachine.add("WAIT", fsm.CBState(wait_for("go%d" % n), outcomes=["done"]), {"done": "done"})
    sm.execute()
"""


@contextlib.contextmanager
def fsmscope_run(tmp_path):
    """``fsmscope run loop.py --exit`` in ``tmp_path``: yields (the address it printed, a function that
    lets machine N end); stopped at the end, its last machine let go."""
    script = tmp_path / "loop.py"
    script.write_text(SCRIPT)
    proc = subprocess.Popen([sys.executable, "-m", "fsmscope", "run", "--exit", str(script)], cwd=tmp_path,
                            env=dict(os.environ, PYTHONPATH=str(ROOT)), stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    lines: queue.Queue = queue.Queue()
    threading.Thread(target=lambda: [lines.put(line) for line in proc.stderr], daemon=True).start()

    def address():
        try:
            found = re.search(r"dashboard at (\S+)", lines.get(timeout=0.05))
        except queue.Empty:
            return None
        return found and found.group(1)

    def let_end(n: int) -> None:
        (tmp_path / ("go%d" % n)).touch()

    try:
        yield wait_for(address, 30, interval=0, what="the dashboard's address"), let_end
    finally:
        for n in (1, 2, 3):
            let_end(n)
        try:
            proc.wait(20)
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()


def showing(page, name: str) -> None:
    """Wait until the page shows machine ``name`` with its stream live and WAIT active."""
    page.wait_for_function("name => document.getElementById('machine-picker').value === name", arg=name)
    page.wait_for_selector('#badge.live')
    page.wait_for_selector('[id="s:/SM_ROOT/WAIT"].active')


def test_the_page_follows_the_newest_machine_the_script_built_when_the_one_shown_ends(browser, tmp_path):
    with fsmscope_run(tmp_path) as (url, let_end):
        page = open_page(browser, url, 1440, 900, scene=False)
        try:
            showing(page, "loop")
            let_end(1)
            showing(page, "loop-2")
            assert "following loop-2, the newest machine of" in page.text_content("#notice")
            let_end(2)
            showing(page, "loop-3")
            assert not page.errors
        finally:
            page.close()


def test_a_machine_chosen_in_the_list_stays_shown_when_the_script_builds_another(browser, tmp_path):
    with fsmscope_run(tmp_path) as (url, let_end):
        page = open_page(browser, url, 1440, 900, scene=False)
        try:
            showing(page, "loop")
            let_end(1)
            showing(page, "loop-2")
            page.select_option("#machine-picker", "loop")
            page.wait_for_selector("#run-state.done")
            let_end(2)
            page.wait_for_function("() => [...document.getElementById('machine-picker').options]"
                                   ".some((o) => o.value === 'loop-3')")
            page.wait_for_timeout(2500)  # a poll of the machines (every 2 s) after loop-3 was listed
            assert page.input_value("#machine-picker") == "loop"
            assert not page.errors
        finally:
            page.close()


def test_a_page_opened_at_an_address_naming_a_machine_stays_on_it(browser, tmp_path):
    with fsmscope_run(tmp_path) as (url, let_end):
        page = open_page(browser, url, 1440, 900, scene=False)
        showing(page, "loop")
        page.close()
        let_end(1)
        page = open_page(browser, url + "#m=loop", 1440, 900, scene=False)
        try:
            page.wait_for_function("() => [...document.getElementById('machine-picker').options]"
                                   ".some((o) => o.value === 'loop-2')")
            page.wait_for_timeout(2500)  # a poll of the machines after loop-2 was listed
            assert page.input_value("#machine-picker") == "loop"
            assert not page.errors
        finally:
            page.close()
