"""The arm's pose on the machine's clock: recorded by the demo at the rate the 3D view draws,
drawn back by the viser scene (live world, or no world at all), and asked for over REST.

Real MuJoCo, real viser, a real `fsmscope demo` process and a real uvicorn.
"""

import json
import threading

import mujoco
import numpy as np
import pytest

from fsm.observation.schema import validate
from fsmscope.server.http_server import ServerThread
from fsmscope.server.testing.polling import wait_for
from scene_support import ViewClient
from server_support import client
from fsmscope.sim.pose import DEFAULT_RATE, PoseLayout, PoseTap
from fsmscope.sim.scene import start_pose_scene, start_scene
from fsmscope.sim.world import ARM_JOINTS, FINGER_JOINTS, HOME_Q, World

FLOAT32 = 1e-6  # viser keeps positions as float32
# A world's xpos after mj_step is the kinematics of the step's starting qpos: it lags the recorded
# qpos by one 2 ms step (under a millimetre for the arm moving fast), plus the recording's rounding.
ONE_STEP = 2e-3


def kinematics(model: mujoco.MjModel, pose: dict) -> mujoco.MjData:
    """The bodies where a pose puts them: forward kinematics of the qpos it describes."""
    data = mujoco.MjData(model)
    data.qpos[:] = PoseLayout(model).qpos(pose)
    mujoco.mj_kinematics(model, data)
    return data


def farthest(drawn: dict, model: mujoco.MjModel, xpos: np.ndarray) -> float:
    """The largest distance between where the scene draws a body and ``xpos``'s place for it."""
    return max(float(np.linalg.norm(p - xpos[model.body(name).id])) for name, p in drawn.items())


def moving_world(seed: int = 0) -> World:
    """A world stepped by the test (no physics thread), its arm on its way from HOME."""
    world = World(seed=seed)
    world.follow(np.array([HOME_Q, HOME_Q + [0.6, -0.3, 0.4, 0.5, -0.4, 0.8]]), 1.0)
    world.step(300)
    return world


@pytest.fixture(scope="module")
def demo_log(headless_demo_log) -> list[dict]:
    """The events of one headless demo episode, as `fsmscope demo --headless` records them."""
    return [json.loads(line) for line in headless_demo_log.read_text().splitlines()]


@pytest.fixture
def scenes():
    made = []
    yield made
    for scene in made:
        scene.stop()


# ---------------------------------------------------------------- recording

def test_a_headless_demo_records_the_pose_at_about_the_view_rate(demo_log):
    root = next(e["path"] for e in demo_log if e["kind"] == "structure")
    began = next(e["t"] for e in demo_log if e["kind"] == "start" and e["path"] == root)
    ended = next(e["t"] for e in demo_log if e["kind"] == "terminate" and e["path"] == root)
    poses = [e for e in demo_log if e["kind"] == "pose" and began <= e["t"] <= ended]
    rate = (len(poses) - 1) / (poses[-1]["t"] - poses[0]["t"])
    assert 0.7 * DEFAULT_RATE <= rate <= 1.05 * DEFAULT_RATE, rate


def test_every_recorded_pose_fits_the_schema_with_the_arm_fingers_and_cube(demo_log):
    poses = [e for e in demo_log if e["kind"] == "pose"]
    assert poses
    assert [validate(e) for e in poses] == [None] * len(poses)
    assert {tuple(e["joints"]) for e in poses} == {tuple(ARM_JOINTS + FINGER_JOINTS)}
    assert {tuple(e["bodies"]) for e in poses} == {("cube",)}


def test_poses_take_their_seq_from_the_machine_clock_between_its_transitions(demo_log):
    events = [e for e in demo_log if e["kind"] != "snapshot"]
    assert [e["seq"] for e in events] == list(range(1, len(events) + 1))  # one counter, no gap
    assert events[0]["kind"] == "structure"  # no pose before the machine describes itself
    kinds = [e["kind"] for e in events]
    first, last = kinds.index("pose"), len(kinds) - 1 - kinds[::-1].index("pose")
    assert kinds[first:last].count("transition") >= 5


def test_an_arm_holding_still_sends_no_pose():
    world = World(seed=1)
    sent = []
    tap = PoseTap(world, sent.append)
    world.step(500)  # the cube settles on the table, the arm holds HOME
    assert tap.poll()
    world.step(500)
    assert not tap.poll()
    world.follow(np.array([HOME_Q, HOME_Q + 0.2]), 0.5)
    world.step(50)
    assert tap.poll()
    assert len(sent) == 2


def test_a_declined_pose_is_offered_again():
    world = World(seed=1)
    answers = iter([False, None])
    offered = []
    tap = PoseTap(world, lambda fields: offered.append(fields) or next(answers))
    assert not tap.poll()
    assert tap.poll()
    assert offered[0] == offered[1]


def test_the_tap_thread_samples_a_running_world_and_stops_cleanly():
    world = World(seed=2).start()
    sent = []
    tap = PoseTap(world, sent.append).start()
    try:
        wait_for(lambda: sent, what="a first pose")
    finally:
        tap.stop()
        world.stop()
    assert not [t.name for t in threading.enumerate() if t.name == "sim-pose"]


def test_pose_fields_map_back_to_the_qpos_they_were_sampled_from():
    world = moving_world()
    layout = PoseLayout(world.model)
    fields = layout.fields(layout.sample(world.data.qpos))
    assert np.allclose(layout.qpos(fields), world.data.qpos, atol=1e-5)


def test_a_joint_the_model_lacks_is_refused():
    with pytest.raises(ValueError, match="no joint 'elbow'"):
        PoseLayout(World(seed=0).model).qpos({"joints": {"elbow": 0.3}})


# ---------------------------------------------------------------- drawing, a page's view at a time

@pytest.fixture
def views():
    """Viser clients made by a test (ViewClient: a page's frame of the 3D view), closed after it."""
    made = []
    yield made
    for view in made:
        view.close()


def recorded_then_moved_on(world):
    """A pose the tap records of ``world`` now, and where its bodies were then; the live arm then moves on."""
    recorded = []
    PoseTap(world, lambda fields: recorded.append((fields, world.data.xpos.copy()))).poll()
    world.step(400)
    return recorded[0]


def test_a_page_s_pose_is_drawn_in_its_own_view_only(scenes, views):
    world = moving_world()
    fields, xpos_then = recorded_then_moved_on(world)
    scene = start_scene(world)
    scenes.append(scene)
    looking_back, live = ViewClient(scene), ViewClient(scene)
    views.extend((looking_back, live))
    scene.show_pose(looking_back.view, fields)
    drawn = scene.drawn_positions(looking_back.id)
    assert {"link1", "hand", "finger_left", "cube"} <= set(drawn)
    assert farthest(drawn, world.model, kinematics(world.model, fields).xpos) < FLOAT32
    assert farthest(drawn, world.model, xpos_then) < ONE_STEP
    assert scene.drawn_label(looking_back.id) == "recorded pose"
    for shown in (scene.drawn_positions(live.id), scene.drawn_positions()):  # the other page, and everyone else
        assert farthest(shown, world.model, world.data.xpos) < FLOAT32
    assert scene.drawn_label(live.id) == scene.drawn_label() != "recorded pose"


def test_the_live_arm_keeps_moving_for_the_other_views_while_one_looks_back(scenes, views):
    world = moving_world()
    fields, _ = recorded_then_moved_on(world)
    scene = start_scene(world)
    scenes.append(scene)
    looking_back, live = ViewClient(scene), ViewClient(scene)
    views.extend((looking_back, live))
    scene.show_pose(looking_back.view, fields)
    world.step(200)
    wait_for(lambda: farthest(scene.drawn_positions(live.id), world.model, world.data.xpos) < FLOAT32,
             what="the live view to follow the arm")
    assert farthest(scene.drawn_positions(looking_back.id), world.model, kinematics(world.model, fields).xpos) < FLOAT32


def test_show_pose_none_brings_the_live_arm_back_to_that_view(scenes, views):
    world = moving_world()
    scene = start_scene(world)
    scenes.append(scene)
    page = ViewClient(scene)
    views.append(page)
    scene.show_pose(page.view, PoseLayout(world.model).fields(PoseLayout(world.model).sample(world.model.qpos0)))
    scene.show_pose(page.view, None)
    world.step(200)
    wait_for(lambda: farthest(scene.drawn_positions(page.id), world.model, world.data.xpos) < FLOAT32,
             what="the live arm drawn in the page's view again")
    assert scene.drawn_label(page.id) == scene.drawn_label() != "recorded pose"


def test_a_view_that_connects_after_its_page_looked_back_is_drawn_the_pose(scenes, views):
    world = moving_world()
    fields, _ = recorded_then_moved_on(world)
    scene = start_scene(world)
    scenes.append(scene)
    view = "late0123456789abcdef"
    scene.show_pose(view, fields)  # the page asked before its frame had connected
    page = ViewClient(scene, view)
    views.append(page)
    assert farthest(scene.drawn_positions(page.id), world.model, kinematics(world.model, fields).xpos) < FLOAT32


def test_a_view_closed_while_looking_back_leaves_the_others_live(scenes, views):
    world = moving_world()
    fields, _ = recorded_then_moved_on(world)
    scene = start_scene(world)
    scenes.append(scene)
    looking_back, live = ViewClient(scene), ViewClient(scene)
    views.append(live)
    scene.show_pose(looking_back.view, fields)
    looking_back.close()
    wait_for(lambda: looking_back.id not in scene.clients(), what="viser to see the view's client go")
    world.step(200)
    wait_for(lambda: farthest(scene.drawn_positions(live.id), world.model, world.data.xpos) < FLOAT32,
             what="the other view to follow the live arm")
    assert scene.drawn_label(live.id) != "recorded pose"


def test_a_pose_scene_draws_its_pose_and_each_page_its_own(scenes, views):
    world = moving_world()
    layout = PoseLayout(world.model)
    last = layout.fields(layout.sample(world.data.qpos))
    earlier = layout.fields(layout.sample(world.model.qpos0))
    scene = start_pose_scene(last)
    scenes.append(scene)
    assert scene.world is None
    assert not [t.name for t in threading.enumerate() if t.name == "sim-scene"]
    first, second = ViewClient(scene), ViewClient(scene)
    views.extend((first, second))
    scene.show_pose(first.view, earlier)
    at_last, at_earlier = kinematics(world.model, last).xpos, kinematics(world.model, earlier).xpos
    assert farthest(scene.drawn_positions(first.id), world.model, at_earlier) < FLOAT32
    assert farthest(scene.drawn_positions(second.id), world.model, at_last) < FLOAT32
    scene.show_pose(first.view, None)  # nothing live: the scene's own pose
    assert farthest(scene.drawn_positions(first.id), world.model, at_last) < FLOAT32


def test_a_pose_scene_refuses_a_pose_of_another_robot():
    with pytest.raises(ValueError, match="no joint 'elbow'"):
        start_pose_scene({"joints": {"elbow": 0.3}})


# ---------------------------------------------------------------- POST /api/scene/pose

@pytest.fixture
def scene_server(scenes):
    scene = start_pose_scene()
    scenes.append(scene)
    srv = ServerThread(scene_url=scene.url, show_pose=scene.show_pose).start()
    try:
        yield srv, scene
    finally:
        srv.stop()


VIEW = "0123456789abcdef0123456789abcdef"


def test_posting_a_pose_draws_it_in_that_page_s_view_only(scene_server, views):
    srv, scene = scene_server
    page, other = ViewClient(scene), ViewClient(scene)
    views.extend((page, other))
    world = moving_world()
    layout = PoseLayout(world.model)
    fields = layout.fields(layout.sample(world.data.qpos))
    with client(srv) as c:
        answer = c.post("/api/scene/pose", json={"view": page.view, "pose": fields})
    assert answer.status_code == 200, answer.text
    assert answer.json() == {"live": False}
    assert farthest(scene.drawn_positions(page.id), world.model, kinematics(world.model, fields).xpos) < FLOAT32
    assert farthest(scene.drawn_positions(other.id), world.model, kinematics(world.model, {}).xpos) < FLOAT32


def test_posting_null_asks_for_the_live_view(scene_server):
    srv, _ = scene_server
    with client(srv) as c:
        answer = c.post("/api/scene/pose", json={"view": VIEW, "pose": None})
    assert (answer.status_code, answer.json()) == (200, {"live": True})


@pytest.mark.parametrize("pose, says", [
    ({"joints": {"j1": "up"}}, "must be"),
    ({"joints": {"j1": 0.1}, "bodies": {"cube": [0.4, 0.1, 0.42]}}, "7 items"),
    ({"bodies": {}}, "joints"),
    ({"joints": {}, "colour": "red"}, "only joints and bodies"),
    ({"joints": {"elbow": 0.3}}, "no joint 'elbow'"),
    ("j1=0.3", "pose"),
], ids=["not a number", "short body pose", "no joints", "another field", "unknown joint", "not an object"])
def test_a_malformed_pose_is_a_422_that_says_why(scene_server, pose, says):
    srv, _ = scene_server
    with client(srv) as c:
        answer = c.post("/api/scene/pose", json={"view": VIEW, "pose": pose})
    assert answer.status_code == 422
    assert says in answer.json()["detail"]


@pytest.mark.parametrize("body", [{"pose": None}, {"view": "short", "pose": None},
                                  {"view": "../" + VIEW, "pose": None}, {"view": 12345678901234567, "pose": None}],
                         ids=["no view", "too short", "not an id", "not a string"])
def test_a_pose_for_no_page_s_view_is_a_422_that_says_why(scene_server, body):
    srv, _ = scene_server
    with client(srv) as c:
        answer = c.post("/api/scene/pose", json=body)
    assert answer.status_code == 422
    assert "view" in answer.json()["detail"]


def test_a_server_without_a_scene_answers_404(live_server):
    with client(live_server) as c:
        answer = c.post("/api/scene/pose", json={"view": VIEW, "pose": None})
    assert (answer.status_code, answer.json()["detail"]) == (404, "no 3D view")


def test_posting_a_pose_needs_the_token(scene_server):
    srv, _ = scene_server
    with client(srv, token=False) as c:
        answer = c.post("/api/scene/pose", json={"view": VIEW, "pose": None})
    assert answer.status_code == 401
