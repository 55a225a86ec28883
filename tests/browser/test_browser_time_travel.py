"""Time travel in the dashboard, in real Chromium: a recorded demo run (real MuJoCo, its arm's pose
recorded) served the way `fsmscope replay LOG --serve` serves it, looked at instant by instant and
compared with what fsm.logfiles.log_reader.seek rebuilds and where the log put the arm; and a live
machine looked back at while it runs."""

from __future__ import annotations

import threading
import time
import urllib.parse

import fsm
import pytest
from browser_support import scene_client, served_page
from fsm.logfiles.log_reader import read_events, seek
from fsmscope.server.cli import replay
from fsmscope.server.http_server import ServerThread
from fsmscope.server.hub import Hub
from fsmscope.server.testing.browser import open_page
from fsmscope.server.testing.polling import wait_for

MACHINE = "pick_place"
STEPPED = ("start", "transition", "terminate")


@pytest.fixture(scope="module")
def events(headless_demo_log):
    return list(read_events(headless_demo_log))


@pytest.fixture(scope="module")
def replayed(headless_demo_log):
    """The log loaded and served as `fsmscope replay --serve` does, with its pose-only 3D view."""
    hub = Hub()
    assert replay.load(hub, replay.reader_of(str(headless_demo_log)), 1.0) > 0
    scene = replay.pose_scene(hub)
    assert scene is not None, "the demo log recorded no pose"
    srv = ServerThread(hub=hub, scene_url=scene.url, show_pose=scene.show_pose).start()
    yield srv, scene
    srv.stop()
    scene.stop()


def open_at(browser, srv, seq=None):
    """The dashboard on the replayed machine (at event ``seq`` through the address, when given)."""
    link = "#m=" + MACHINE + ("" if seq is None else "&seq=%d" % seq)
    page = open_page(browser, srv.url + link, scene=False)
    if seq is not None:
        shown_at(page, seq)
    return page


def shown_at(page, seq):
    wait_for(lambda: page.evaluate("window.fsmscope.instant.seq") == seq, timeout=10,
             what="the page to show event %d" % seq)


def active_paths(status: dict) -> list[str]:
    return sorted(path + "/" + label for path, entry in status["containers"].items()
                  for label in entry["active"] if label != "None")


def shown_status(page) -> dict:
    return page.evaluate("window.fsmscope.status.toDict()")


def rebuilt(headless_demo_log, seq) -> dict:
    return seek(headless_demo_log, MACHINE, seq).status.to_dict()


def first_transition(events, path):
    return next(e for e in events if e["kind"] == "transition" and e["path"] == path)


def test_a_replay_opens_paused_at_its_first_event(browser, replayed, events):
    page = open_at(browser, replayed[0])
    first = events[0]["seq"]
    shown_at(page, first)
    assert page.evaluate("window.fsmscope.instant") == {"past": True, "seq": first, "t": events[0]["t"],
                                                        "playing": False}
    page.close()


def test_an_address_with_seq_shows_the_state_seek_rebuilds_at_that_event(browser, replayed, headless_demo_log, events):
    at = first_transition(events, "/SM_ROOT/TASK/PLACE")["seq"]
    page = open_at(browser, replayed[0], at)
    shown, expected = shown_status(page), rebuilt(headless_demo_log, at)
    assert active_paths(shown) == active_paths(expected) and "/SM_ROOT/TASK/PLACE/LOWER" in active_paths(shown)
    assert {p: c["userdata"] for p, c in shown["containers"].items()} == \
        {p: c["userdata"] for p, c in expected["containers"].items()}
    page.close()


def test_the_graph_lights_the_states_active_at_the_instant(browser, replayed, events):
    at = first_transition(events, "/SM_ROOT/TASK/PICK")["seq"]
    page = open_at(browser, replayed[0], at)
    page.wait_for_function("document.querySelector('#graph g.node.active[id=\"s:/SM_ROOT/TASK/PICK/DESCEND\"]')")
    page.close()


def test_the_run_pill_says_the_state_of_the_instant_shown(browser, replayed, events):
    page = open_at(browser, replayed[0], first_transition(events, "/SM_ROOT/TASK/PICK")["seq"])
    page.wait_for_function("document.getElementById('run-state').textContent === 'running'")
    page.close()


def test_the_arm_is_drawn_where_the_log_put_it_at_the_instant(browser, replayed, events):
    srv, scene = replayed
    carried = first_transition(events, "/SM_ROOT/TASK/PLACE")["seq"]  # TRANSPORT done: the cube in the air
    pose = [e for e in events if e["kind"] == "pose" and e["seq"] <= carried][-1]
    page = open_page(browser, srv.url + "#m=" + MACHINE + "&seq=%d" % carried)  # its 3D view drawn
    shown_at(page, carried)
    assert page.evaluate("window.fsmscope.status.pose.seq") == pose["seq"]
    cube = pose["bodies"]["cube"][:3]
    client = scene_client(scene, page)
    wait_for(lambda: all(abs(a - b) < 1e-4 for a, b in zip(scene.drawn_positions(client)["cube"], cube)), timeout=10,
             what="the 3D view to draw the cube where the log put it")
    page.close()


def test_dragging_on_the_timeline_shows_the_state_at_the_instant_dragged_to(browser, replayed, headless_demo_log, events):
    page = open_at(browser, replayed[0], events[0]["seq"])
    box = page.locator(".tl-canvas").bounding_box()
    left = box["x"] + page.evaluate("async () => (await import('/timeline_draw.js')).LAYOUT.labelW") + 5
    y = box["y"] + 10  # the time axis
    page.mouse.move(left, y)
    page.mouse.down()
    page.mouse.move(left + (box["x"] + box["width"] - left) * 0.45, y, steps=12)
    page.mouse.up()
    wait_for(lambda: page.evaluate("window.fsmscope.instant.seq") > events[30]["seq"], timeout=10,
             what="the drag to move the instant into the run")
    shown = shown_status(page)  # whatever instant the drag has reached: the state rebuilt there
    assert active_paths(shown) == active_paths(rebuilt(headless_demo_log, shown["last_seq"]))
    page.close()


def test_stepping_forward_and_back_crosses_a_nested_transition(browser, replayed, headless_demo_log, events):
    pick_ends = next(e for e in events if e["kind"] == "terminate" and e["path"] == "/SM_ROOT/TASK/PICK")
    after = next(e for e in events if e["seq"] > pick_ends["seq"] and e["kind"] in STEPPED)
    assert after["path"] == "/SM_ROOT/TASK"  # PICK ended, then TASK moves on: the next step is a level up
    page = open_at(browser, replayed[0], pick_ends["seq"])
    page.keyboard.press("ArrowRight")
    shown_at(page, after["seq"])
    assert active_paths(shown_status(page)) == active_paths(rebuilt(headless_demo_log, after["seq"]))
    page.keyboard.press("ArrowLeft")
    shown_at(page, pick_ends["seq"])
    assert active_paths(shown_status(page)) == active_paths(rebuilt(headless_demo_log, pick_ends["seq"]))
    page.close()


def test_stepping_within_one_container_skips_the_other_levels(browser, replayed, events):
    task = [e for e in events if e["path"] == "/SM_ROOT/TASK" and e["kind"] in STEPPED]
    assert any(e["kind"] in STEPPED and e["path"] != "/SM_ROOT/TASK" for e in events
               if task[1]["seq"] < e["seq"] < task[2]["seq"])  # other levels move in between
    page = open_at(browser, replayed[0], task[1]["seq"])
    row_y = page.evaluate("""async () => {  // the middle of the second row (TASK) of the timeline
        const { LAYOUT, rowsTop } = await import('/timeline_draw.js');
        return rowsTop() + LAYOUT.rowH * 1.5;
    }""")
    page.locator(".tl-canvas").click(position={"x": 30, "y": row_y})
    page.keyboard.press("Shift+ArrowRight")
    shown_at(page, task[2]["seq"])
    page.close()


def test_clicking_an_event_log_row_jumps_to_its_event(browser, replayed, events):
    at = first_transition(events, "/SM_ROOT/TASK/PLACE")["seq"]
    page = open_at(browser, replayed[0], at)
    page.wait_for_selector("#log .log-row.at[data-seq='%d']" % at)  # the log drawn around the instant: no row moves under the click
    earlier = first_transition(events, "/SM_ROOT/TASK/PICK")["seq"]
    page.click("#log .log-row[data-seq='%d']" % earlier)
    shown_at(page, earlier)
    page.wait_for_selector("#log .log-row.at[data-seq='%d']" % earlier)  # the log follows the instant
    page.close()


def test_the_log_marks_the_instant_and_greys_what_came_after(browser, replayed, events):
    at = first_transition(events, "/SM_ROOT/TASK/PICK")["seq"]
    page = open_at(browser, replayed[0], at)
    page.wait_for_selector("#log .log-row.at[data-seq='%d']" % at)
    later = page.eval_on_selector_all("#log .log-row.later", "rows => rows.map(r => Number(r.dataset.seq))")
    assert later and min(later) > at
    page.close()


def test_the_instants_row_is_in_the_middle_of_the_event_log(browser, replayed, events):
    at = first_transition(events, "/SM_ROOT/TASK/PLACE")["seq"]
    page = open_at(browser, replayed[0], at)
    page.wait_for_selector("#log .log-row.at[data-seq='%d']" % at)
    # Rows out of view are drawn at an estimated height (style.css): the row is centred again once
    # the rows around it have their real heights.
    page.wait_for_function("""() => {
        const row = document.querySelector('#log .log-row.at').getBoundingClientRect();
        const log = document.querySelector('#log').getBoundingClientRect();
        return Math.abs(row.top + row.height / 2 - (log.top + log.height / 2)) <= row.height;
    }""", timeout=5000)
    page.close()


def test_playing_moves_the_instant_forward_through_the_recorded_states(browser, replayed, headless_demo_log, events):
    page = open_at(browser, replayed[0], events[0]["seq"])
    page.keyboard.press("Space")
    wait_for(lambda: page.evaluate("window.fsmscope.instant.seq") > events[20]["seq"], timeout=15,
             what="playing to move the instant on")
    page.keyboard.press("Space")
    wait_for(lambda: not page.evaluate("window.fsmscope.instant.playing"), timeout=5, what="the pause")
    seq = page.evaluate("window.fsmscope.instant.seq")
    assert active_paths(shown_status(page)) == active_paths(rebuilt(headless_demo_log, seq))
    page.close()


def first_change(events, path: str, after: int) -> tuple[dict, str]:
    """The first event of container ``path`` after seq ``after`` whose ``changes`` (a step's transition's
    or terminate's) give a key another value (the demo's states write every output key, most with the
    value it had), and that key."""
    values: dict = {}
    for e in events:
        if e["path"] == path and e["kind"] == "start":
            values = dict(e["userdata"])
        elif e["path"] == path and "changes" in e:
            for key, value in e["changes"].items():
                if e["seq"] > after and (key not in values or values[key] != value):
                    return e, key
            values.update(e["changes"])
    raise LookupError("no change of %s's userdata after %d" % (path, after))


def test_the_userdata_a_transition_changed_shows_its_old_value(browser, replayed, events):
    written, key = first_change(events, "/SM_ROOT/TASK", 10)
    page = open_at(browser, replayed[0], written["seq"])
    page.select_option("#ud-container", "/SM_ROOT/TASK")
    row = page.wait_for_selector("#userdata tr.ud-row.changed[data-key='%s']" % key)
    assert "was " in row.text_content() or "new key" in row.text_content()
    page.close()


def test_a_keys_history_lists_every_change_and_jumps_to_one(browser, replayed, events):
    writes = [e["seq"] for e in events if e["path"] == "/SM_ROOT/TASK" and (
        ("attempts" in e.get("changes", {})) or (e["kind"] == "start" and "attempts" in e["userdata"]))]
    page = open_at(browser, replayed[0], events[-1]["seq"])
    page.select_option("#ud-container", "/SM_ROOT/TASK")
    page.hover("#userdata tr.ud-row[data-key='attempts']")
    page.click("#userdata tr.ud-row[data-key='attempts'] .ud-history-btn")
    items = page.wait_for_selector("ol.ud-key-history li").evaluate(
        "li => [...li.parentElement.children].map(x => Number(x.dataset.seq))")
    assert items == writes
    page.click("ol.ud-key-history li[data-seq='%d']" % writes[-1])
    shown_at(page, writes[-1])
    page.close()


# ---------------------------------------------------------------- a live machine, looked back at

def ticking_machine(stop: threading.Event):
    """A -> B -> A ... every 20 ms until ``stop`` is set."""
    def tick(ud):
        time.sleep(0.02)
        ud.n = ud.n + 1
        return "done" if stop.is_set() else "next"
    sm = fsm.StateMachine(outcomes=["done"])
    sm.userdata.n = 0
    with sm:
        fsm.StateMachine.add("A", fsm.CBState(tick, outcomes=["next", "done"], input_keys=["n"], output_keys=["n"]),
                             transitions={"next": "B"})
        fsm.StateMachine.add("B", fsm.CBState(tick, outcomes=["next", "done"], input_keys=["n"], output_keys=["n"]),
                             transitions={"next": "A"})
    return sm


@pytest.fixture
def live_page(browser):
    stop = threading.Event()
    sm = ticking_machine(stop)
    with served_page(browser, sm, "ticker") as page:
        runner = threading.Thread(target=sm.execute, daemon=True)
        runner.start()
        wait_for(lambda: page.evaluate("window.fsmscope.liveStatus.last_seq") > 40, timeout=10, what="some events")
        yield page
        stop.set()
        runner.join(5)


def look_back(page) -> int:
    """Click the sixth row of the live log, scrolled up to with the wheel as a user does (the log follows
    the newest row until the user scrolls it away: a row scrolled into view otherwise moves on)."""
    page.hover("#log")
    page.mouse.wheel(0, -100000)
    row = page.locator("#log .log-row[data-seq]").nth(5)
    seq = int(row.get_attribute("data-seq"))
    row.click()
    shown_at(page, seq)
    return seq


def test_looking_back_at_a_live_machine_says_how_far_behind_it_is(live_page):
    look_back(live_page)
    said = live_page.wait_for_function(  # drawn at the next frame after the instant changed
        "() => { const t = document.querySelector('.tl-status').textContent;"
        " return t.startsWith('viewing the past: ') && t; }").json_value()
    assert " events behind" in said


def test_a_live_machine_runs_on_while_the_page_looks_back(live_page):
    seq = look_back(live_page)
    live = live_page.evaluate("window.fsmscope.liveStatus.last_seq")
    wait_for(lambda: live_page.evaluate("window.fsmscope.liveStatus.last_seq") > live + 20, timeout=10,
             what="the machine to go on")
    assert live_page.evaluate("window.fsmscope.instant.seq") == seq


def test_back_to_live_shows_the_machine_as_it_is_now(live_page):
    look_back(live_page)
    live_page.click("button.tl-live")
    wait_for(lambda: not live_page.evaluate("window.fsmscope.instant.past"), timeout=5, what="live again")
    assert live_page.evaluate("window.fsmscope.status === window.fsmscope.liveStatus")
    live_page.wait_for_selector("button.tl-live", state="hidden")


def paces(page) -> list:
    """The pace (s) each of the server's stream clients of the live machine asked for."""
    return sorted(client.pace for client in page.server.hub.get("ticker").feed.clients)


def test_a_page_looking_back_asks_for_the_live_events_four_times_a_second_only(live_page):
    assert paces(live_page) == [0.0]
    look_back(live_page)
    wait_for(lambda: paces(live_page) == [0.25], timeout=5, what="the page to ask for a pace")


def test_back_to_live_asks_for_every_event_as_it_comes_again(live_page):
    look_back(live_page)
    wait_for(lambda: paces(live_page) == [0.25], timeout=5, what="the page to ask for a pace")
    live_page.click("button.tl-live")
    wait_for(lambda: paces(live_page) == [0.0], timeout=5, what="the page to ask for every event")
