"""ROS bags of a SMACH run, written by the tests with rosbags' writers, laid out as smach_ros's
IntrospectionServer publishes (topics ``<server>/smach/container_structure`` and ``..._status``, the
smach_msgs types, a structure message per container every 2 s, a status per container at start
("Initial state"), at each of its transitions and every 2 s; ``local_data`` base64 of a protocol 2
pickle on noetic, the raw pickle before it and on ROS 2).

The run is a pick and place: /SM_ROOT: FIND --found--> GRASP (a Concurrence of ARM and GRIPPER)
--grasped--> PLACE (MOVE --moved--> RELEASE --released--> placed) --placed--> succeeded.
"""

from __future__ import annotations

from pathlib import Path

from fsmscope.interop.testing import write_bag as write

T0 = 1_700_000_000.0
ROOT, GRASP, PLACE = "/SM_ROOT", "/SM_ROOT/GRASP", "/SM_ROOT/PLACE"
STRUCTURES = {
    ROOT: (["FIND", "GRASP", "PLACE"], [("found", "FIND", "GRASP"), ("missing", "FIND", "aborted"),
                                        ("grasped", "GRASP", "PLACE"), ("failed", "GRASP", "FIND"),
                                        ("placed", "PLACE", "succeeded"), ("dropped", "PLACE", "aborted")],
           ["succeeded", "aborted"]),
    GRASP: (["ARM", "GRIPPER"], [("reached", "ARM", "grasped"), ("closed", "GRIPPER", "grasped")], ["grasped", "failed"]),
    PLACE: (["MOVE", "RELEASE"], [("moved", "MOVE", "RELEASE"), ("released", "RELEASE", "placed"),
                                  ("blocked", "MOVE", "dropped"), ("preempted", "RELEASE", "None")],
            ["placed", "dropped"]),
}
INITIAL = {ROOT: ["FIND"], GRASP: ["ARM", "GRIPPER"], PLACE: ["MOVE"]}
# (seconds after T0, container, active states, its userdata): what smach_ros publishes for the run.
STATUSES = [
    (0.0, ROOT, ["None"], {"target": "cup", "tries": 0}),
    (0.0, GRASP, [], {}),
    (0.0, PLACE, ["None"], {}),
    (1.0, ROOT, ["GRASP"], {"target": "cup", "tries": 1, "seen": (0.4, 0.1)}),
    (1.5, GRASP, ["GRIPPER"], {"force": 2.5}),
    (1.8, GRASP, [], {"force": 2.5}),
    (1.9, ROOT, ["PLACE"], {"target": "cup", "tries": 1, "seen": (0.4, 0.1)}),
    (2.0, ROOT, ["PLACE"], {"target": "cup", "tries": 1, "seen": (0.4, 0.1)}),
    (2.0, GRASP, [], {"force": 2.5}),
    (2.0, PLACE, ["MOVE"], {"pose": [1.0, 2.0]}),
    (2.5, PLACE, ["RELEASE"], {"pose": [1.0, 2.0], "opened": True}),
    (4.0, ROOT, ["None"], {"target": "cup", "tries": 1, "seen": (0.4, 0.1), "done": {"ok"}}),
    (4.0, GRASP, [], {"force": 2.5}),
    (4.0, PLACE, ["None"], {"pose": [1.0, 2.0], "opened": True}),
]


def messages(server: str = "pick_place") -> list[tuple[float, str, str, dict]]:
    """(t, topic, kind, fields) of the run, in time order, every container's structure at 0, 2 and 4 s."""
    out = []
    for t in (0.0, 2.0, 4.0):
        for path, (children, edges, outcomes) in STRUCTURES.items():
            out.append((t, "structure", {"path": path, "children": children, "internal_outcomes": [e[0] for e in edges],
                                         "outcomes_from": [e[1] for e in edges], "outcomes_to": [e[2] for e in edges],
                                         "container_outcomes": outcomes}))
    for t, path, active, userdata in STATUSES:
        out.append((t, "status", {"path": path, "initial_states": INITIAL[path], "active_states": active,
                                  "userdata": userdata, "info": "HEARTBEAT"}))
    out.sort(key=lambda m: m[0])
    return [(T0 + t, "/%s/smach/container_%s" % (server, kind), kind, fields) for t, kind, fields in out]


def write_bag(path: Path, layout: str, runs: list[tuple[float, str, str, dict]] | None = None) -> Path:
    """The run (or ``runs``) written to a bag at ``path`` in ``layout`` (interop.testing.write_bag)."""
    return write(path, layout, messages() if runs is None else runs)
