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
from server.http_server import ServerThread
from server.testing.polling import wait_for
from server_support import client
from sim.pose import DEFAULT_RATE, PoseLayout, PoseTap
from sim.scene import start_pose_scene, start_scene
from sim.world import ARM_JOINTS, FINGER_JOINTS, HOME_Q, World

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


# ---------------------------------------------------------------- drawing

def test_show_pose_draws_the_bodies_where_the_recorded_pose_puts_them(scenes):
    world = moving_world()
    recorded = []
    PoseTap(world, lambda fields: recorded.append((fields, world.data.xpos.copy()))).poll()
    world.step(400)  # the live arm moves on
    scene = start_scene(world)
    scenes.append(scene)
    fields, xpos_then = recorded[0]
    scene.show_pose(fields)
    drawn = scene.drawn_positions()
    assert {"link1", "hand", "finger_left", "cube"} <= set(drawn)
    assert farthest(drawn, world.model, kinematics(world.model, fields).xpos) < FLOAT32
    assert farthest(drawn, world.model, xpos_then) < ONE_STEP
    assert farthest(drawn, world.model, world.data.xpos) > 0.05  # not the live arm
    assert scene.label.text == "recorded pose"


def test_show_pose_none_brings_the_live_world_back(scenes):
    world = moving_world()
    scene = start_scene(world, always=True)
    scenes.append(scene)
    scene.show_pose(PoseLayout(world.model).fields(PoseLayout(world.model).sample(world.model.qpos0)))
    scene.show_pose(None)
    wait_for(lambda: farthest(scene.drawn_positions(), world.model, world.data.xpos) < FLOAT32,
             what="the live arm drawn again")


def test_a_pose_scene_has_no_world_and_draws_the_pose_it_is_given(scenes):
    world = moving_world()
    layout = PoseLayout(world.model)
    fields = layout.fields(layout.sample(world.data.qpos))
    scene = start_pose_scene(fields)
    scenes.append(scene)
    assert scene.world is None
    assert not [t.name for t in threading.enumerate() if t.name == "sim-scene"]
    placed = kinematics(world.model, fields).xpos
    assert farthest(scene.drawn_positions(), world.model, placed) < FLOAT32
    scene.show_pose(None)  # nothing live to go back to: the pose stays
    assert farthest(scene.drawn_positions(), world.model, placed) < FLOAT32


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


def test_posting_a_pose_draws_it_in_the_scene(scene_server):
    srv, scene = scene_server
    world = moving_world()
    layout = PoseLayout(world.model)
    fields = layout.fields(layout.sample(world.data.qpos))
    with client(srv) as c:
        answer = c.post("/api/scene/pose", json={"pose": fields})
    assert answer.status_code == 200, answer.text
    assert answer.json() == {"live": False}
    assert farthest(scene.drawn_positions(), world.model, kinematics(world.model, fields).xpos) < FLOAT32


def test_posting_null_asks_for_the_live_view(scene_server):
    srv, _ = scene_server
    with client(srv) as c:
        answer = c.post("/api/scene/pose", json={"pose": None})
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
        answer = c.post("/api/scene/pose", json={"pose": pose})
    assert answer.status_code == 422
    assert says in answer.json()["detail"]


def test_a_server_without_a_scene_answers_404(live_server):
    with client(live_server) as c:
        answer = c.post("/api/scene/pose", json={"pose": None})
    assert (answer.status_code, answer.json()["detail"]) == (404, "no 3D view")


def test_posting_a_pose_needs_the_token(scene_server):
    srv, _ = scene_server
    with client(srv, token=False) as c:
        answer = c.post("/api/scene/pose", json={"pose": None})
    assert answer.status_code == 401
