"""Userdata, feedback and items are encoded JSON-safe (docs/events.md, "Encoding values"); never pickled."""

import dataclasses
import enum
import json
import math
import time

import fsm
import numpy as np
from fsm.observation.encoding import DEFAULT_CAP, dumps, encode, encode_userdata, encode_written, encoded
from hypothesis import given
from hypothesis import strategies as st


def strict_json(value) -> str:
    return json.dumps(value, allow_nan=False)


class Color(enum.Enum):
    RED = 1


@dataclasses.dataclass
class Pose:
    x: float
    y: float
    tags: tuple


def test_json_values_pass_through_unchanged():
    value = {"a": [1, 2.5, "s", None, True], "b": {"c": False}}
    assert encode(value) == value


def test_tuples_and_sets_become_lists():
    assert encode((1, 2)) == [1, 2]
    assert encode({3}) == [3]


def test_dict_keys_that_are_not_strings_become_strings():
    assert encode({1: "a", (2, 3): "b"}) == {"1": "a", "(2, 3)": "b"}


def test_non_finite_floats_become_strings():
    assert encode([math.nan, math.inf, -math.inf]) == ["NaN", "Infinity", "-Infinity"]


def test_integers_beyond_64_bits_become_strings():
    assert encode(2 ** 70) == str(2 ** 70)


def test_dataclasses_become_dicts_of_their_fields():
    assert encode(Pose(1.0, 2.0, ("a",))) == {"x": 1.0, "y": 2.0, "tags": ["a"]}


def test_enums_become_class_dot_name():
    assert encode(Color.RED) == "Color.RED"


def test_numpy_arrays_and_scalars_become_lists_and_numbers():
    assert encode(np.array([[1, 2], [3, 4]])) == [[1, 2], [3, 4]]
    assert encode(np.float32(0.5)) == 0.5


def test_other_objects_become_a_truncated_repr():
    class Thing:
        def __repr__(self):
            return "T" * 500
    encoded = encode(Thing())
    assert set(encoded) == {"$repr"} and encoded["$repr"].startswith("TTT") and len(encoded["$repr"]) <= 203


def test_a_raising_repr_does_not_raise():
    class Broken:
        def __repr__(self):
            raise RuntimeError("no")
    assert "unrepresentable" in encode(Broken())["$repr"]


def test_a_value_over_the_cap_becomes_a_truncation_marker():
    encoded = encode(list(range(10_000)))
    assert encoded["$truncated"] is True and encoded["size"] > DEFAULT_CAP and len(encoded["repr"]) <= 203


def test_nesting_deeper_than_sixteen_levels_is_cut():
    value = []
    for _ in range(40):
        value = [value]
    text = strict_json(encode(value, cap=None))
    assert "$repr" in text


def test_a_read_only_input_is_encoded_as_the_value_it_wraps():
    assert encode(fsm.Const(Pose(0.0, 1.0, ()))) == {"x": 0.0, "y": 1.0, "tags": []}


def test_userdata_keys_are_encoded_one_by_one_under_the_cap():
    encoded = encode_userdata({"small": 1, "big": "x" * (DEFAULT_CAP + 1)})
    assert encoded["small"] == 1 and encoded["big"]["$truncated"] is True


def shared_levels(levels=14, width=10):
    """A list of ``width`` references to a list of ``width`` references to ... : small in memory, ``width ** levels``
    items when written out."""
    value = []
    for _ in range(levels):
        value = [value] * width
    return value


def test_a_value_that_is_huge_only_when_expanded_is_cut_at_the_cap_in_no_time():
    started = time.monotonic()
    encoded = encode(shared_levels())
    assert time.monotonic() - started < 0.5
    assert encoded["$truncated"] is True and DEFAULT_CAP < encoded["size"] < 2 * DEFAULT_CAP
    assert encoded["repr"].startswith("[[[[[[[[[[[[[[[], []") and len(encoded["repr"]) <= 203


def test_a_value_cut_for_its_depth_is_shown_by_a_short_repr_made_in_no_time():
    value = shared_levels()
    for _ in range(20):
        value = [value]
    started = time.monotonic()
    text = strict_json(encode(value, cap=None))
    assert time.monotonic() - started < 0.5 and len(text) < 1000


def test_a_numpy_array_too_big_for_the_cap_is_a_marker_before_it_is_listed():
    started = time.monotonic()
    encoded = encode(np.zeros(10_000_000))
    assert time.monotonic() - started < 0.5
    assert encoded["$truncated"] is True and encoded["size"] >= 10_000_000


def test_a_shared_value_is_written_at_each_of_its_places():
    pose = [1.0, 2.0]
    assert encode({"a": pose, "b": [pose, pose]}) == {"a": [1.0, 2.0], "b": [[1.0, 2.0], [1.0, 2.0]]}


def test_a_value_that_holds_itself_is_cut_where_it_comes_back():
    loop = [1]
    loop.append(loop)
    assert encode(loop) == [1, {"$repr": "[...]"}]


def test_an_int_with_more_digits_than_python_writes_is_a_marker():
    assert encode(10 ** 5000) == {"$repr": "<int of 16610 bits>"}
    assert encode({10 ** 5000: 1}) == {"<int of 16610 bits>": 1}


json_like = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text() | st.binary(),
    lambda children: st.lists(children) | st.tuples(children, children) | st.dictionaries(
        st.text() | st.integers(), children),
    max_leaves=30)


@given(json_like)
def test_any_nested_value_encodes_to_strict_json(value):
    strict_json(encode(value))


def test_the_observers_of_one_event_share_one_encoding_of_it():
    event = {"seq": 1, "kind": "transition"}
    first = encoded(event)
    assert first == dumps(event)
    assert encoded(event) is first


def test_another_event_is_encoded_for_itself_even_when_equal():
    event = {"seq": 1, "kind": "transition"}
    first = encoded(event)
    copy = dict(event)
    assert encoded(copy) is not first and encoded(copy) == first


def test_a_short_list_of_numbers_is_encoded_as_a_copy_the_machine_may_change_after():
    pose = [0.1, 0.2, 3]
    encoded = encode(pose)
    pose[0] = 9.0
    assert encoded == [0.1, 0.2, 3]


def test_a_short_list_with_an_infinite_number_still_says_it():
    assert encode((1.0, float("inf"), float("nan"))) == [1.0, "Infinity", "NaN"]


written_values = st.one_of(st.integers(-(2 ** 70), 2 ** 70), st.floats(), st.booleans(), st.none(),
                           st.text(max_size=3), st.just("x" * (DEFAULT_CAP + 1)), st.lists(st.integers(), max_size=2))


@given(st.dictionaries(st.one_of(st.text(max_size=3), st.integers(0, 3)), written_values, max_size=3))
def test_a_steps_writes_encode_as_any_userdata_does(written):
    assert json.dumps(encode_written(dict(written)), sort_keys=True) == json.dumps(encode_userdata(written), sort_keys=True)


def test_a_steps_plain_writes_are_their_own_encoding():
    written = {"count": 3, "name": "pick", "ok": True, "ratio": 0.5, "none": None}
    assert encode_written(written) is written
