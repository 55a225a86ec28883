"""The 3D view is each page's own, in real Chromium at 1440 x 900: two dashboard pages, each with
viser's page in its frame, on the simulated arm (real MuJoCo, real viser, the demo's machine and
its recorded pose, served in this process so the test can ask the scene what it told each viser
client), and on a recorded demo log replayed with no simulation. A page looking back shows the
pose of its own instant; the other pages stay as they were, also after it closes."""

from __future__ import annotations

import re
import threading

import fsm
import mujoco
import numpy as np
import pytest
from browser_support import scene_client
from fsm.logfiles.log_reader import read_events
from fsmscope.server.cli import replay
from fsmscope.server.cli.demo import pose_events
from fsmscope.server.http_server import ServerThread
from fsmscope.server.hub import Hub
from fsmscope.server.testing.browser import open_page
from fsmscope.server.testing.polling import wait_for

MACHINE = "pick_place"
FLOAT32 = 1e-6  # viser keeps positions as float32


@pytest.fixture(scope="module")
def live_arm():
    """The demo's arm running its episodes in real time, its machine and pose served with the 3D view
    as `fsmscope demo` serves them: (server, scene, world)."""
    from fsmscope.sim.demo import SimDemo
    from fsmscope.sim.pose import PoseTap

    fsm.set_loggers(*(lambda msg: None,) * 4)
    demo = SimDemo(seed=0, scene=True)
    machine = demo.build_machine()
    tap = PoseTap(demo.world, pose_events(fsm.attach(machine, name=MACHINE)))
    srv = ServerThread(scene_url=demo.scene.url, show_pose=demo.scene.show_pose).start()
    srv.hub.add_local(machine, name=MACHINE, can_start=False)
    episodes = threading.Thread(target=demo.run, kwargs={"machine_factory": lambda world: machine}, daemon=True)
    tap.start()
    episodes.start()
    try:
        yield srv, demo.scene
    finally:
        demo.request_stop()
        tap.stop()
        episodes.join(10)
        srv.stop()
        demo.close()


@pytest.fixture(scope="module")
def replayed(headless_demo_log):
    """A recorded demo episode served as `fsmscope replay --serve` serves it, with its pose-only 3D view."""
    hub = Hub()
    assert replay.load(hub, replay.reader_of(str(headless_demo_log)), 1.0) > 0
    scene = replay.pose_scene(hub)
    srv = ServerThread(hub=hub, scene_url=scene.url, show_pose=scene.show_pose).start()
    try:
        yield srv, scene
    finally:
        srv.stop()
        scene.stop()


@pytest.fixture(scope="module")
def events_of(headless_demo_log) -> list[dict]:
    return list(read_events(headless_demo_log))


@pytest.fixture
def pages(browser):
    """Pages a test opens (``open_``), closed after it unless it closed them; none may have a script error."""
    made = []

    def open_(srv, link=""):
        page = open_page(browser, srv.url + "#m=" + MACHINE + link, 1440, 900)
        page.wait_for_selector("#scene-pane:not([hidden]) iframe")
        made.append(page)
        return page

    yield open_
    for page in made:
        assert not page.errors
        if not page.is_closed():
            page.close()


def frame_state(page) -> str | None:
    """What viser's page in ``page``'s frame says the state is (its panel's 'state:' line)."""
    found = re.search(r"state: (.*)", page.frame_locator("#scene-pane iframe").locator("body").inner_text())
    return found.group(1).strip() if found else None


def frame_saying(page, wanted, what: str) -> str:
    return wait_for(lambda: (lambda said: said if said and wanted(said) else None)(frame_state(page)), timeout=30,
                    interval=0.1, what=lambda: "the frame to say %s; it says %r" % (what, frame_state(page)))


def look_back(page) -> int:
    """Click an event of the log, as a user does: the page shows that instant; its seq."""
    row = page.locator("#log .log-row[data-seq]").nth(10)
    seq = int(row.get_attribute("data-seq"))
    row.click()
    wait_for(lambda: page.evaluate("window.fsmscope.instant.seq") == seq, timeout=10, what="the page at the event")
    assert page.evaluate("window.fsmscope.status.pose") is not None
    return seq


def placed(scene, pose: dict) -> dict[str, np.ndarray]:
    """Where ``pose`` (a status's pose) puts each moving body: forward kinematics on the scene's model."""
    data = mujoco.MjData(scene.model)
    data.qpos[:] = scene.layout.qpos(pose)
    mujoco.mj_kinematics(scene.model, data)
    return {name: data.xpos[scene.model.body(name).id] for name in scene.drawn_positions()}


def farthest(drawn: dict, place: dict) -> float:
    return max(float(np.linalg.norm(p - place[name])) for name, p in drawn.items())


def drawing(scene, client: int, pose: dict) -> bool:
    """Whether viser was last told to show ``client`` the bodies where ``pose`` puts them."""
    return farthest(scene.drawn_positions(client), placed(scene, pose)) < FLOAT32


def moving(scene, client: int) -> bool:
    """Whether ``client`` is shown the shared arm (the live one) and it moves on, within 15 s."""
    before = scene.drawn_positions(client)
    return bool(wait_for(lambda: farthest(scene.drawn_positions(client), before) > 1e-3, timeout=15, interval=0.05,
                         what="the live arm to move in the view")) \
        and farthest(scene.drawn_positions(client), scene.drawn_positions()) == 0.0


def test_a_page_looking_back_leaves_the_other_pages_3d_view_live(live_arm, pages):
    srv, scene = live_arm
    watching, scrubbing = pages(srv), pages(srv)
    frame_saying(watching, lambda said: said != "recorded pose", "a live state")
    look_back(scrubbing)
    frame_saying(scrubbing, lambda said: said == "recorded pose", "'recorded pose'")
    frame_saying(watching, lambda said: said != "recorded pose", "the live state still")
    wait_for(lambda: drawing(scene, scene_client(scene, scrubbing), scrubbing.evaluate("window.fsmscope.status.pose")),
             timeout=10, what="the scrubbing page's view to be drawn its instant's pose")
    assert moving(scene, scene_client(scene, watching))


def test_a_page_closed_while_looking_back_leaves_the_others_live(live_arm, pages):
    srv, scene = live_arm
    watching, scrubbing = pages(srv), pages(srv)
    look_back(scrubbing)
    frame_saying(scrubbing, lambda said: said == "recorded pose", "'recorded pose'")
    scrubbing.close()
    first = frame_saying(watching, lambda said: said != "recorded pose", "a live state")
    frame_saying(watching, lambda said: said not in (first, "recorded pose"), "the next live state")
    wait_for(lambda: list(scene.clients()) == [scene_client(scene, watching)], timeout=10,
             what="the closed page's frame to leave viser")
    assert moving(scene, scene_client(scene, watching))


def test_two_pages_at_different_instants_each_show_their_own_pose(replayed, pages, events_of):
    srv, scene = replayed
    poses = [e for e in events_of if e["kind"] == "pose"]
    early, late = poses[len(poses) // 4]["seq"], poses[3 * len(poses) // 4]["seq"]
    first, second = pages(srv, "&seq=%d" % early), pages(srv, "&seq=%d" % late)
    for page, seq in ((first, early), (second, late)):
        wait_for(lambda: page.evaluate("window.fsmscope.instant.seq") == seq, timeout=10, what="the page at %d" % seq)
    for page in (first, second):
        wait_for(lambda: drawing(scene, scene_client(scene, page), page.evaluate("window.fsmscope.status.pose")),
                 timeout=10, what="each page's view to be drawn its own instant's pose")
    assert farthest(scene.drawn_positions(scene_client(scene, first)),
                    scene.drawn_positions(scene_client(scene, second))) > 0.01  # two poses, not one
    second.keyboard.press("ArrowLeft")  # the second page scrubs on
    wait_for(lambda: second.evaluate("window.fsmscope.instant.seq") < late, timeout=10, what="the step back")
    wait_for(lambda: drawing(scene, scene_client(scene, second), second.evaluate("window.fsmscope.status.pose")),
             timeout=10, what="the second page's view to follow it")
    assert drawing(scene, scene_client(scene, first), first.evaluate("window.fsmscope.status.pose"))
