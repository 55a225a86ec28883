"""interop.safe_pickle: smach_ros's pickled userdata read as plain data, nothing a pickle names ever run."""

from __future__ import annotations

import base64
import math
import os
import pickle

import numpy
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from interop import safe_pickle


class Shell:
    """A pickle that runs a shell command when the standard unpickler loads it."""

    def __init__(self, marker: str) -> None:
        self.marker = marker

    def __reduce__(self):
        return (os.system, ("touch %s" % self.marker,))


class Pose:
    def __init__(self) -> None:
        self.x = 1.0


def test_a_pickle_that_calls_os_system_runs_nothing_and_says_what_it_named(tmp_path):
    marker = tmp_path / "ran"
    value = safe_pickle.loads(pickle.dumps({"goal": Shell(str(marker))}, 2))
    assert not marker.exists()
    assert repr(value["goal"]) == "<opaque posix.system>"


def test_a_class_instance_is_a_marker_with_its_type_name():
    value = safe_pickle.loads(pickle.dumps([Pose()], 2))
    assert isinstance(value[0], safe_pickle.Opaque) and repr(value[0]) == "<opaque %s.Pose>" % __name__


def test_a_numpy_array_is_a_marker():
    value = safe_pickle.loads(pickle.dumps({"scan": numpy.zeros(3)}, 2))
    assert isinstance(value["scan"], safe_pickle.Opaque) and "numpy" in repr(value["scan"])


plain = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False) | st.text() | st.binary(),
    lambda inner: st.lists(inner, max_size=4) | st.tuples(inner, inner)
    | st.dictionaries(st.text(max_size=8), inner, max_size=4)
    | st.frozensets(st.integers() | st.text(max_size=4), max_size=4),
    max_leaves=20)


@settings(max_examples=200, deadline=None)
@given(value=plain, protocol=st.integers(0, pickle.HIGHEST_PROTOCOL))
def test_plain_data_comes_back_equal_whatever_the_protocol(value, protocol):
    assert safe_pickle.loads(pickle.dumps(value, protocol)) == value


def test_local_data_reads_noetic_base64_and_the_raw_pickle_of_older_releases():
    data = {"n": 1, "where": [0.5, math.pi]}
    raw = pickle.dumps(data, 2)
    assert safe_pickle.local_data(base64.b64encode(raw).decode()) == data
    assert safe_pickle.local_data(raw) == data


def test_python_2_str_pickles_read_as_text():
    assert safe_pickle.loads(b"\x80\x02}q\x00U\x01aq\x01U\x01xq\x02s.") == {"a": "x"}


def test_bytes_that_are_no_pickle_say_so():
    with pytest.raises(ValueError, match="no pickle"):
        safe_pickle.local_data("not a pickle")
