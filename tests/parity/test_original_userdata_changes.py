"""The userdata of an original container compared after a step (fsm/observation/original_userdata.py):
a change is a value that differs from the last one reported, by type and value, in place too; an
unchanged value is none, whatever its kind."""

import pytest
from fsm.observation.original_userdata import UserdataWatch


class Point:
    """A user's value: encoded each time, a change when its encoding is."""

    def __init__(self, x):
        self.x = x

    def __repr__(self):
        return "Point(%r)" % self.x


class Touchy:
    """A user's value whose comparison raises."""

    def __eq__(self, other):
        raise RuntimeError("no comparing me")

    __hash__ = object.__hash__

    def __repr__(self):
        return "Touchy()"


@pytest.fixture
def watched(core):
    """The original's UserData holding a value of each kind, and a watch that reported it at the start."""
    ud = core.UserData()
    ud.name, ud.count, ud.ratio, ud.pose, ud.table, ud.point = "arm", 3, 0.5, [0.1, 0.2], {"a": [1]}, Point(1)
    watch = UserdataWatch()
    watch.snapshot(ud)
    return ud, watch


def test_nothing_changed_is_no_change(watched):
    ud, watch = watched
    assert watch.changes(ud) == {}


def test_values_rewritten_equal_are_no_change(watched):
    ud, watch = watched
    ud.name, ud.count, ud.ratio = "".join(["a", "rm"]), int("3"), float("0.5")
    ud.pose, ud.table, ud.point = [0.1, 0.2], {"a": [1]}, Point(1)
    assert watch.changes(ud) == {}


def test_an_equal_value_of_another_type_is_a_change(watched):
    ud, watch = watched
    ud.count, ud.ratio = 3.0, True
    assert watch.changes(ud) == {"count": 3.0, "ratio": True}


def test_a_container_changed_in_place_is_a_change_and_then_none(watched):
    ud, watch = watched
    ud.pose.append(0.3)
    ud.table["a"].append(2)
    assert watch.changes(ud) == {"pose": [0.1, 0.2, 0.3], "table": {"a": [1, 2]}}
    assert watch.changes(ud) == {}


def test_a_new_key_is_a_change(watched):
    ud, watch = watched
    ud.extra = None
    assert watch.changes(ud) == {"extra": None}


def test_a_users_value_is_a_change_when_its_encoding_is(watched):
    ud, watch = watched
    ud.point.x = 2
    [(key, encoded)] = watch.changes(ud).items()
    assert key == "point" and "2" in str(encoded)


def test_a_value_whose_comparison_raises_is_compared_by_its_encoding(watched):
    ud, watch = watched
    ud.list_of_touchy = [Touchy()]
    assert list(watch.changes(ud)) == ["list_of_touchy"]
    ud.list_of_touchy = [Touchy()]
    assert watch.changes(ud) == {}
