"""The userdata panel at 1440x900 and 1920x1080 (issue 31, item 5): a key's "history" button can be
seen and clicked, a short value takes one line (a long one too, cut, until its row is clicked), and
the keys a transition marks changed are those whose value changed, not every key it wrote."""

from __future__ import annotations

import threading

import fsm
import pytest
from browser_support import page_at
from fsmscope.server.http_server import ServerThread

ROOT = "/SM_ROOT"
# Nine keys: WRITE counts `attempts` (0 -> 1), writes `target` again with the value it had, and
# leaves the others, short values and one long `plan`, as they were.
SHORT = {"frame": "world", "gripper": "open", "mode": "auto", "speed": 0.25, "target": "bin_A", "tool": "suction",
         "attempts": 0, "retries_left": 3}
PLAN = [{"x": round(0.1 * i, 2), "y": round(0.2 * i, 2), "z": 0.3, "yaw": 0.0} for i in range(40)]

# Each row of the panel: its key, class, height, and its history button's box and visibility once
# scrolled into the pane's view.
ROWS = """() => [...document.querySelectorAll('#userdata tr.ud-row')].map((row) => {
  const button = row.querySelector('.ud-history-btn');
  button.scrollIntoView({ block: 'nearest' });
  const b = button.getBoundingClientRect();
  const pane = document.getElementById('userdata').getBoundingClientRect();
  const hit = document.elementFromPoint(b.x + b.width / 2, b.y + b.height / 2);
  return { key: row.dataset.key, cls: row.className, height: row.getBoundingClientRect().height,
           button: { width: b.width, visible: getComputedStyle(button).visibility === 'visible',
                     inPane: b.left >= pane.left && b.right <= pane.right, reachable: button.contains(hit) } };
})"""


def writing_machine(gate: threading.Event):
    """WRITE (see SHORT) -> WAIT (until ``gate``) -> done."""
    def write(ud):
        ud.attempts = ud.attempts + 1
        ud.target = ud.target
        return "go"

    sm = fsm.StateMachine(outcomes=["done"])
    for key, value in {**SHORT, "plan": PLAN}.items():
        sm.userdata[key] = value
    with sm:
        fsm.StateMachine.add("WRITE", fsm.CBState(write, outcomes=["go"], input_keys=["attempts", "target"],
                                                  output_keys=["attempts", "target"]), {"go": "WAIT"})
        fsm.StateMachine.add("WAIT", fsm.CBState(lambda ud: gate.wait(120) and "go", outcomes=["go"]), {"go": "done"})
    return sm


@pytest.fixture(scope="module")
def waiting():
    """A server showing the machine while it waits in WAIT, WRITE's transition its last."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    gate = threading.Event()
    sm = writing_machine(gate)
    srv = ServerThread().start()
    srv.hub.add_local(sm, name="writer")
    runner = threading.Thread(target=sm.execute)
    runner.start()
    try:
        yield srv
    finally:
        gate.set()
        runner.join(10)
        srv.stop()


@pytest.fixture(params=[(1440, 900), (1920, 1080)], ids=["1440", "1920"])
def page(browser, waiting, request):
    with page_at(browser, waiting.url + "#m=writer", "#badge.live", *request.param, scene=False) as page:
        page.wait_for_selector('.tree-row.active[data-path="/SM_ROOT/WAIT"]')
        page.select_option("#ud-container", ROOT)
        page.wait_for_selector('#userdata tr.ud-row[data-key="plan"]')
        yield page


def rows(page) -> dict:
    return {row["key"]: row for row in page.evaluate(ROWS)}


def test_every_keys_history_button_can_be_seen_and_clicked(page):
    for row in rows(page).values():
        button = row["button"]
        assert button["visible"] and button["inPane"] and button["reachable"], row
        assert button["width"] >= 40, row  # it was 4 px wide
    page.click('#userdata tr.ud-row[data-key="attempts"] .ud-history-btn')
    page.wait_for_selector("ol.ud-key-history li")


def test_a_key_takes_one_line_and_a_long_value_is_cut_until_its_row_is_clicked(page):
    line = page.evaluate("() => parseFloat(getComputedStyle(document.querySelector('#userdata tr.ud-row td.value')).lineHeight)")
    shown = rows(page)
    assert len(shown) == 9
    for row in shown.values():
        assert row["height"] < 2 * line, row  # rows were about 93 px tall
    page.click('#userdata tr.ud-row[data-key="plan"] td.value')
    page.wait_for_selector('#userdata tr.ud-row[data-key="plan"] td.value pre')
    assert rows(page)["plan"]["height"] > 5 * line
    assert '"yaw": 0' in page.text_content('#userdata tr.ud-row[data-key="plan"] td.value')


def test_only_the_keys_whose_value_changed_are_marked_changed(page):
    shown = rows(page)
    marked = sorted(key for key, row in shown.items() if "changed" in row["cls"].split())
    assert marked == ["attempts"]  # `target` was written with the value it had
    assert "was 0" in page.text_content('#userdata tr.ud-row[data-key="attempts"] td.value')
