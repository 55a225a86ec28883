"""fsmscope.interop.safe_pickle: smach_ros's pickled userdata read as plain data, nothing a pickle names ever run."""

from __future__ import annotations

import base64
import math
import os
import pickle
import time

import numpy
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fsmscope.interop import safe_pickle


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


def shared_tuples(levels: int = 40, width: int = 10) -> bytes:
    """The pickle of a tuple of ``width`` references to a tuple of ``width`` references to ...: a few hundred
    bytes that hashing reads ``width ** levels`` times."""
    value: tuple = ()
    for _ in range(levels):
        value = (value,) * width
    return pickle.dumps(value, 2)[2:-1]  # without PROTO and STOP


@pytest.mark.timeout(20)
def test_a_dict_key_that_hashing_would_read_forever_is_refused_at_once():
    data = b"\x80\x02}" + shared_tuples() + b"K\x01s."  # {key: 1}, written opcode by opcode: making it here would hash it
    started = time.monotonic()
    with pytest.raises(safe_pickle.TooCostly, match="hashing more than"):
        safe_pickle.loads(data)
    assert time.monotonic() - started < 2


@pytest.mark.timeout(20)
def test_a_set_of_such_keys_is_refused_at_once():
    data = b"\x80\x02c__builtin__\nset\n](" + shared_tuples() + b"e\x85R."  # set([key])
    with pytest.raises(safe_pickle.TooCostly, match="hashing more than"):
        safe_pickle.loads(data)


@pytest.mark.timeout(20)
def test_a_marker_called_again_and_again_keeps_its_name():
    data = b"\x80\x02cos\nsystem\n" + b")R" * 200_000 + b"."  # os.system()()()...
    assert repr(safe_pickle.loads(data)) == "<opaque os.system(...)>"


def test_a_pickle_naming_more_globals_than_are_kept_shares_one_marker_for_the_rest():
    names = b"".join(b"cmodule\nname%d\n" % i for i in range(safe_pickle.MAX_NAMES + 1))
    value = safe_pickle.loads(b"\x80\x02(" + names + b"l.")  # [module.name0, module.name1, ...]
    assert value[0].type_name == "module.name0"
    assert value[-1].type_name == "(one of more than %d globals)" % safe_pickle.MAX_NAMES
