"""The userdata "Set initial state" sends a ROS robot (fsmscope/interop/ros_controls.py): a protocol 2
pickle made only of plain values, which smach_ros unpickles on the robot, so nothing else may be in it."""

import math
import pickle

import pytest

from fsmscope.interop import safe_pickle
from fsmscope.interop.ros_controls import plain


def test_plain_values_go_as_they_are_and_read_back_the_same():
    userdata = {"goal": [0.4, 0.1, {"frame": "map"}], "tries": 3, "ok": True, "note": None, "pose": (1.0, 2.0)}
    assert plain(userdata) == userdata
    assert safe_pickle.loads(pickle.dumps(plain(userdata), 2)) == userdata


@pytest.mark.parametrize("value, where", [
    ({"cmd": b"x"}, "userdata.cmd is a bytes"),
    ({"seen": {1, 2}}, "userdata.seen is a set"),
    ({"path": [1, object()]}, "userdata.path[1] is a object"),
    ({"speed": math.nan}, "userdata.speed is nan"),
    ({1: "a"}, "a key 1 that is not a string"),
])
def test_anything_else_is_refused_saying_where(value, where):
    with pytest.raises(ValueError, match=where.replace("[", r"\[").replace("]", r"\]")):
        plain(value)
