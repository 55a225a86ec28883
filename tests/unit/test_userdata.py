"""BEHAVIORS.md section D: userdata, remapping, key enforcement, cb_interface."""

import fsm as smach
import pytest

from smach_support import Out, machine, userdata


def _run_one(fn, parent_data=None, remapping=None, **keys):
    """Run ``fn(ud)`` as the only state of a machine whose userdata starts as ``parent_data``."""
    sm = smach.StateMachine(outcomes=["done"])
    for k, v in (parent_data or {}).items():
        sm.userdata[k] = v
    with sm:
        smach.StateMachine.add("S", Out(fn, **keys), remapping=remapping)
    assert sm.execute() == "done"
    return sm


@pytest.mark.parametrize("read", [lambda ud: ud.x, lambda ud: ud["x"]])
def test_reading_an_undeclared_key_raises_invalid_user_code_error(logs, read):
    errors = []

    def body(ud):
        with pytest.raises(smach.InvalidUserCodeError) as info:
            read(ud)
        errors.append(str(info.value))
        return "done"
    _run_one(body, {"x": 1}, input_keys=["a"])
    assert errors == ["Reading from SMACH userdata key 'x' but the only keys that were declared as input to "
                      "this state were: ('a',). This key needs to be declared as input to this state. "]


def test_reading_an_output_only_key_raises_invalid_user_code_error(logs):
    def body(ud):
        with pytest.raises(smach.InvalidUserCodeError):
            ud.x
        return "done"
    _run_one(body, {"x": 1}, output_keys=["x"])
    assert logs.error[0].startswith("InvalidUserCodeError: Reading from SMACH userdata key 'x'")


def test_writing_an_undeclared_key_logs_an_error_and_drops_the_value(logs):
    def body(ud):
        ud.x = 1
        ud["y"] = 2
        return "done"
    sm = _run_one(body, output_keys=["out"])
    assert logs.error == [
        "Writing to SMACH userdata key 'x' but the only keys that were declared as output from this state were: ('out',).",
        "Writing to SMACH userdata key 'y' but the only keys that were declared as output from this state were: ('out',)."]
    assert sm.userdata.keys() == []


def test_remapped_reads_and_writes_reach_the_parent_key_immediately():
    seen = []

    def body(ud):
        seen.append(ud.local_in)
        ud.local_out = ud.local_in + 1
        seen.append(sm.userdata.parent_out)
        return "done"
    sm = smach.StateMachine(outcomes=["done"])
    sm.userdata.parent_in = 41
    with sm:
        smach.StateMachine.add("S", Out(body, input_keys=["local_in"], output_keys=["local_out"]),
                               remapping={"local_in": "parent_in", "local_out": "parent_out"})
    sm.execute()
    assert seen == [41, 42]
    assert "local_out" not in sm.userdata


def test_keys_a_state_did_not_declare_are_invisible_to_it():
    seen = []
    _run_one(lambda ud: seen.append(("k" in ud, "a" in ud)) or "done", {"k": 1, "a": 2}, input_keys=["a"])
    assert seen == [(False, True)]


@pytest.mark.parametrize("read", [lambda ud: ud.k, lambda ud: ud["k"], lambda ud: hasattr(ud, "k")])
def test_reading_a_missing_key_logs_available_keys_and_raises_bare_key_error(logs, read):
    ud = userdata(a=1)
    with pytest.raises(KeyError) as info:
        read(ud)
    assert info.value.args == ()
    assert logs.error == ["Userdata key 'k' not available. Available keys are: ['a']"]


def test_reading_a_declared_key_missing_from_the_parent_raises_key_error(logs):
    def body(ud):
        with pytest.raises(KeyError):
            ud.k
        return "done"
    _run_one(body, input_keys=["k"])
    assert logs.error == ["Userdata key 'k' not available. Available keys are: []"]


class Plain:
    def __init__(self):
        self.v = 1

    def bump(self):
        return self.v + 1


class Slotted:
    __slots__ = ("v",)

    def __init__(self):
        self.v = 1


def test_input_only_list_dict_and_slots_values_are_raw_and_mutable_in_place():
    def body(ud):
        ud.lst.append(2)
        ud.dct["b"] = 2
        ud.msg.v = 5
        return "done"
    lst, dct, msg = [1], {"a": 1}, Slotted()
    _run_one(body, {"lst": lst, "dct": dct, "msg": msg}, input_keys=["lst", "dct", "msg"])
    assert lst == [1, 2] and dct == {"a": 1, "b": 2} and msg.v == 5


def test_input_only_object_with_a_dict_is_wrapped_in_const():
    seen = []
    _run_one(lambda ud: seen.append(type(ud.obj)) or "done", {"obj": Plain()}, input_keys=["obj"])
    assert seen == [smach.Const]


def test_input_output_object_is_returned_raw():
    obj = Plain()
    seen = []
    _run_one(lambda ud: seen.append(ud.obj) or "done", {"obj": obj}, io_keys=["obj"])
    assert seen == [obj]


def test_setting_an_attribute_on_a_const_raises_type_error_and_leaves_the_original(logs):
    obj = Plain()

    def body(ud):
        with pytest.raises(TypeError):
            ud.obj.v = 99
        return "done"
    _run_one(body, {"obj": obj}, input_keys=["obj"])
    assert obj.v == 1
    assert logs.error == ["Attempting to set 'v' but this member is read-only."]


def test_deleting_an_attribute_on_a_const_raises_type_error(logs):
    const = smach.Const(Plain())
    with pytest.raises(TypeError):
        del const.v
    assert logs.error == ["Attempting to delete 'v' but this member is read-only."]


def test_methods_of_an_input_only_object_can_be_called():
    seen = []
    _run_one(lambda ud: seen.append((ud.obj.bump(), ud.obj.v)) or "done", {"obj": Plain()}, input_keys=["obj"])
    assert seen == [(2, 1)]


def test_remapper_keys_lists_the_local_names_of_remapped_input_keys():
    seen = []
    _run_one(lambda ud: seen.append((sorted(ud.keys()), "local" in ud)) or "done", {"parent": 1, "same": 2, "x": 3},
             remapping={"local": "parent"}, input_keys=["local", "same", "absent"])
    assert seen == [(["local", "same"], True)]


def test_container_copies_declared_input_keys_on_entry_and_output_keys_on_exit():
    sm = machine(["done"], [("S", Out(lambda ud: setattr(ud, "b", ud.a * 2) or "done", input_keys=["a"],
                                      output_keys=["b"]), {})], input_keys=["a"], output_keys=["b"])
    parent = userdata(a=4, other=0)
    assert sm.execute(parent) == "done"
    assert parent.b == 8
    assert sm.userdata.keys() == ["a", "b"]


def test_missing_input_key_logs_userdata_error_then_copy_warning(logs):
    sm = machine(["done"], [("S", Out("done"), {})], input_keys=["k"])
    assert sm.execute(smach.UserData()) == "done"
    assert [entry for entry in logs.all if entry[0] in ("warn", "error")] == [
        ("error", "Userdata key 'k' not available. Available keys are: []"),
        ("warn", "Attempting to copy input key 'k', but this key does not exist.")]


def test_missing_output_key_logs_a_copy_warning(logs):
    sm = machine(["done"], [("S", Out("done"), {})], output_keys=["k"])
    assert sm.execute(smach.UserData()) == "done"
    assert logs.warn == ["Attempting to copy output key 'k', but this key does not exist."]


def test_nested_container_without_input_keys_sees_none_of_the_parent_data():
    seen = []
    inner = smach.StateMachine(outcomes=["done"])
    with inner:
        smach.StateMachine.add("S", Out(lambda ud: seen.append(inner.userdata.keys()) or "done"))
    outer = machine(["done"], [("INNER", inner, {})])
    outer.userdata.secret = 1
    assert outer.execute() == "done"
    assert seen == [[]]


def test_tuple_key_arguments_raise_type_error():
    with pytest.raises(TypeError, match=r'can only concatenate tuple \(not "list"\) to tuple'):
        smach.State(outcomes=["done"], input_keys=("x",))


@pytest.mark.parametrize("outcomes", [("a", "b"), {"a", "b"}, iter(["a", "b"])])
def test_outcomes_argument_accepts_any_iterable(outcomes):
    assert sorted(smach.State(outcomes=outcomes).get_registered_outcomes()) == ["a", "b"]


def test_cb_interface_has_no_io_keys_parameter():
    with pytest.raises(TypeError):
        smach.cb_interface(outcomes=["done"], io_keys=["x"])


def test_cbstate_merges_the_callbacks_declared_keys_and_outcomes():
    @smach.cb_interface(outcomes=["found"], input_keys=["a"], output_keys=["b"])
    def cb(ud, factor):
        ud.b = ud.a * factor
        return "found"
    state = smach.CBState(cb, cb_args=[3], outcomes=["lost"], input_keys=["c"])
    assert sorted(state.get_registered_outcomes()) == ["found", "lost"]
    assert sorted(state.get_registered_input_keys()) == ["a", "c"]
    assert sorted(state.get_registered_output_keys()) == ["b"]
    sm = machine(["found", "lost"], [("CB", state, {})])
    sm.userdata.a = 2
    assert sm.execute() == "found"
    assert sm.userdata.b == 6


def test_cb_interface_result_is_callable_and_reports_tuples():
    @smach.cb_interface(outcomes=["done"], input_keys=["a"])
    def cb(ud):
        return "done"
    assert smach.has_smach_interface(cb)
    assert cb(None) == "done"
    assert cb.get_registered_outcomes() == ("done",)
    assert cb.get_registered_input_keys() == ("a",)
    assert cb.get_registered_output_keys() == ()


def test_cbstate_passes_cb_args_and_kwargs():
    seen = []
    state = smach.CBState(lambda ud, a, b=0: seen.append((a, b)) or "done", cb_args=[1], cb_kwargs={"b": 2},
                          outcomes=["done"])
    assert machine(["done"], [("CB", state, {})]).execute() == "done"
    assert seen == [(1, 2)]


def test_extract_copies_keys_to_their_local_names_and_merge_copies_them_back_under_the_remapped_names(logs):
    parent = smach.UserData()
    parent.p = [1]
    parent.q = 2
    local = parent.extract(["p", "q"], {"local_p": "p"})
    assert sorted(local.keys()) == ["local_p", "q"]
    assert local.local_p == [1] and local.local_p is not parent.p
    into = smach.UserData()
    into.merge(local, ["local_p"], {"local_p": "back"})
    assert into.keys() == ["back"] and into.back is not local.local_p
    parent.extract([], {"a": "p", "b": "p"})
    assert logs.error == ["SMACH userdata remapping is not one-to-one: {'a': 'p', 'b': 'p'}"]
