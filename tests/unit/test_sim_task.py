"""The simulated arm and its pick-and-place machine, on real MuJoCo physics (headless).

Fast mode (physics on demand) throughout, except in the preemption tests from the
start of TRANSPORT on: there physics runs at real time, so that a preempt arrives
from another thread mid-transport, as a REST call or an 'sm_stop' message would, and
"stopped within 0.2 s of simulated time" measures the same thing it would live.
"""

import math
import socket
import threading
import time
import urllib.request

import numpy as np
import pytest

pytest.importorskip("mujoco")

import fsm  # noqa: E402
from fsm.ros.actionlib import GoalStatus, SimpleActionClient  # noqa: E402
from fsm.ros.bus import Bus  # noqa: E402
from fsmscope.server.testing.polling import wait_for  # noqa: E402

from fsmscope.sim.demo import SimDemo  # noqa: E402
from fsmscope.sim.ik import IKSolver, tool_down_rotation  # noqa: E402
from fsmscope.sim.world import ARM_JOINTS, CUBE_REGION, HOME_Q, TABLE_Z, World, load_model  # noqa: E402


@pytest.fixture(autouse=True)
def _quiet():
    def quiet(msg):
        pass
    fsm.set_loggers(quiet, quiet, quiet, quiet)


@pytest.fixture
def demo_factory():
    made = []

    def make(**kw):
        kw.setdefault("scene", False)
        kw.setdefault("bus", Bus())
        d = SimDemo(**kw)
        made.append(d)
        return d

    yield make
    for d in made:
        d.close()
    time.sleep(0.05)
    left = [t.name for t in threading.enumerate() if t.name.startswith(("sim-", "action:"))]
    assert not left, left


# ---------------------------------------------------------------- world and IK

def test_cube_placement_is_seeded_and_on_the_table():
    a, b, c = World(seed=7), World(seed=7), World(seed=8)
    pa, pb, pc = a.cube_pose(), b.cube_pose(), c.cube_pose()
    assert pa == pb
    assert pa != pc
    for p in (pa, pc):
        assert CUBE_REGION[0][0] <= p["x"] <= CUBE_REGION[0][1]
        assert CUBE_REGION[1][0] <= p["y"] <= CUBE_REGION[1][1]
        assert p["z"] == pytest.approx(TABLE_Z + 0.02)


def test_ik_reaches_tool_down_poses_and_refuses_unreachable_ones():
    ik = IKSolver(load_model(), "tcp", ARM_JOINTS)
    for pos, yaw in (([0.32, 0.05, 0.43], 0.5), ([0.5, 0.28, 0.43], -0.7), ([0.4, -0.25, 0.57], 0.0)):
        q = ik.solve(HOME_Q, pos, tool_down_rotation(yaw))
        assert q is not None
        p, r = ik.forward(q)
        assert np.linalg.norm(p - pos) < 1e-3
        assert np.allclose(r, tool_down_rotation(yaw), atol=1e-2)
    assert ik.solve(HOME_Q, [1.5, 0.0, 0.43], tool_down_rotation(0.0)) is None


def test_fast_physics_is_deterministic_for_a_seed(demo_factory):
    runs = []
    for _ in range(2):
        d = demo_factory(seed=3, fast=True)
        info = d.run(episodes=1)[0]
        runs.append((info["outcome"], info["sim_time"], d.world.cube_pose()))
        d.close()
    assert runs[0] == runs[1]


# ---------------------------------------------------------------- servers

def test_move_to_aborts_with_a_reason_and_gripper_reports_held(demo_factory):
    d = demo_factory(seed=1, fast=True)
    mv = SimpleActionClient("move_to", d.bus)
    assert mv.wait_for_server(2.0)
    mv.send_goal({"pose": {"x": 1.5, "y": 0.0, "z": 0.45, "yaw": 0.0}})
    assert mv.wait_for_result(10.0)
    assert mv.get_state() == GoalStatus.ABORTED
    assert mv.get_goal_status_text() == "no IK solution"
    mv.send_goal({"waypoint": "nowhere"})
    assert mv.wait_for_result(10.0)
    assert mv.get_state() == GoalStatus.ABORTED

    feedback = []
    c = d.world.cube_pose()
    mv.send_goal({"pose": {"x": c["x"], "y": c["y"], "z": c["z"] + 0.005, "yaw": c["yaw"]}},
                 feedback_cb=feedback.append)
    assert mv.wait_for_result(10.0)
    assert mv.get_state() == GoalStatus.SUCCEEDED
    assert feedback and feedback[0]["distance"] > feedback[-1]["distance"]
    assert mv.get_result()["distance"] < 0.01
    gr = SimpleActionClient("gripper", d.bus)
    gr.send_goal({"command": "close"})
    assert gr.wait_for_result(10.0)
    assert gr.get_state() == GoalStatus.SUCCEEDED and gr.get_result()["held"] is True
    gr.send_goal({"command": "open"})
    assert gr.wait_for_result(10.0)
    assert gr.get_result()["held"] is False


# ---------------------------------------------------------------- the task machine

def test_five_seeded_episodes_place_the_cube_within_2cm(demo_factory):
    d = demo_factory(seed=0, fast=True)
    results = d.run(episodes=5)
    assert [r["outcome"] for r in results] == ["succeeded"] * 5, results
    for r in results:
        assert r["cube_target_distance"] < 0.02, r
        assert r["attempts"] == 1
    cube = d.world.cube_pose()
    assert cube["z"] == pytest.approx(TABLE_Z + 0.02, abs=0.003)  # resting on the table
    assert np.allclose(d.world.arm_q(), HOME_Q, atol=0.02)


def test_too_heavy_cube_retries_three_times_then_aborts_at_home(demo_factory):
    d = demo_factory(seed=2, fast=True)
    d.world.set_cube_mass(5.0)  # 49 N against at most ~25 N of friction from the pads
    [info] = d.run(episodes=1)
    labels = [text for _, text in d.world.labels]
    assert info["outcome"] == "aborted"
    assert info["attempts"] == 4  # the first grasp and 3 retries
    assert labels.count("PICK/APPROACH") == 4
    assert labels.count("PICK/REOPEN") == 4
    assert "PLACE/TRANSPORT" not in labels
    assert labels[-2:] == ["SAFE_HOME", "episode 0: aborted"]
    assert np.allclose(d.world.arm_q(), HOME_Q, atol=0.02)
    assert d.world.cube_target_distance() > 0.1


def _preempt_during_transport(d, preempt):
    """Run one episode, real time from TRANSPORT on; ``preempt`` 0.5 s into TRANSPORT."""
    w = d.world
    w.label_hooks.append(lambda text: text == "PLACE/TRANSPORT" and w.set_speed(1.0))
    out = {}
    machine = d.build_machine()
    runner = threading.Thread(target=lambda: out.update(outcome=machine.execute()))
    runner.start()
    wait_for(lambda: w.label == "PLACE/TRANSPORT" or not runner.is_alive(), 30.0, interval=0.002,
             what=lambda: "PLACE/TRANSPORT; the arm is at " + w.label)
    assert w.label == "PLACE/TRANSPORT", w.label  # not an episode that ended before transporting
    t_transport = w.time
    w.sleep(0.5)
    speed_before = float(np.max(np.abs(w.arm_qvel())))
    preempt(machine)
    runner.join(10.0)
    assert not runner.is_alive()
    # joint speeds near zero 0.2 s of simulated time after the machine serviced the preempt (counted
    # from the preempt, the simulator's real-time thread ran on while a loaded computer had the
    # machine's thread wait: how soon it stops on a loaded computer is not this test's to say)
    w.sleep(0.2)
    speed_after = float(np.max(np.abs(w.arm_qvel())))
    return out.get("outcome"), speed_before, speed_after, t_transport


@pytest.mark.parametrize("how", ["request_preempt", "sm_stop"])
def test_preempt_during_transport_stops_the_arm(demo_factory, how):
    d = demo_factory(seed=4, fast=True)
    if how == "request_preempt":
        def preempt(m):
            m.request_preempt()
    else:
        def preempt(m):
            d.bus.publish("sm_stop", {"reason": "test"})
    outcome, before, after, _ = _preempt_during_transport(d, preempt)
    assert outcome == "preempted"
    assert before > 0.2, before  # it was moving
    assert after < 0.05, after
    assert d.world.object_held()  # the gripper kept its grip
    q = d.world.arm_q()
    d.world.sleep(0.3)
    assert np.max(np.abs(d.world.arm_q() - q)) < 0.01  # and it stays put


# ---------------------------------------------------------------- the 3D view

def test_scene_binds_loopback_and_stop_frees_the_port():
    from fsmscope.sim.scene import start_scene

    w = World(seed=0).start()
    try:
        sc = start_scene(w)
        try:
            assert sc.server.get_host() == "127.0.0.1"
            body = urllib.request.urlopen(sc.url, timeout=5).read()
            assert b"<html" in body.lower()
            w.label = "PICK/APPROACH"
            sc._draw(force=True)
            assert sc.label.text == "PICK/APPROACH"
        finally:
            sc.stop()
        with socket.socket() as s:  # nobody listens on the port any more
            s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # TIME_WAIT is fine
            s.bind(("127.0.0.1", sc.port))
    finally:
        w.stop()
    assert not [t for t in threading.enumerate() if t.name.startswith("sim-")]
    assert math.isfinite(w.time)
