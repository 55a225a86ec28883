"""BEHAVIORS.md section D, the original SMACH and fsm side by side: userdata, remapping, keys."""

from parity_support import kit, outcome_of


def run_one(sm, body, **keys):
    """A machine of one state S running ``body(ud)`` with the given key declarations (and remapping):
    (the machine, the list of what body returned)."""
    k = kit(sm)
    got = []
    built = k.machine(["done"], [("S", k.Out(lambda ud: got.append(body(ud)) or "done", **{
        name: value for name, value in keys.items() if name != "remapping"}), {}, keys.get("remapping", {}))])
    return built, got


def test_reading_an_undeclared_key_raises_naming_the_declared_ones(parity):
    def scenario(side):
        built, got = run_one(side.sm, lambda ud: (outcome_of(lambda: ud.x), outcome_of(lambda: ud["x"])),
                             input_keys=["a"], output_keys=["x"])
        built.userdata.x = 1
        outcome_of(built.execute)
        return got
    [(attribute, item)] = parity.same(scenario)["result"]
    assert attribute == item == ("raised", "InvalidUserCodeError", (
        "Reading from SMACH userdata key 'x' but the only keys that were declared as input to this state were: "
        "('a',). This key needs to be declared as input to this state. "))


def test_writing_an_undeclared_key_logs_and_drops_the_value(parity):
    def scenario(side):
        def write(ud):
            ud.x = 1
            ud["y"] = 2
        built, got = run_one(side.sm, write, output_keys=["out"])
        return outcome_of(built.execute), built.userdata.keys()
    same = parity.same(scenario)
    assert same["result"] == (("returned", "done"), [])
    assert [message for level, message in same["logs"] if level == "error"] == [
        "Writing to SMACH userdata key '%s' but the only keys that were declared as output from this state were: "
        "('out',)." % key for key in ("x", "y")]


def test_a_remapped_key_reads_and_writes_the_parents_key_at_once(parity):
    def scenario(side):
        built = None

        def body(ud):
            seen = ud.local
            ud.local = seen + 1
            return seen, built.userdata.parent, "local" in ud, "parent" in ud, "hidden" in ud
        built, got = run_one(side.sm, body, input_keys=["local"], output_keys=["local"],
                             remapping={"local": "parent"})
        built.userdata.parent = 1
        built.userdata.hidden = 0
        return outcome_of(built.execute), got, built.userdata.parent
    assert parity.same(scenario)["result"] == (("returned", "done"), [(1, 2, True, False, False)], 2)


def test_a_missing_declared_key_logs_and_raises_a_bare_key_error_hasattr_too(parity):
    def scenario(side):
        ud = side.sm.UserData()
        ud.present = 1
        return outcome_of(lambda: ud.k), outcome_of(lambda: ud["k"]), outcome_of(lambda: hasattr(ud, "k"))
    same = parity.same(scenario)
    assert same["result"] == (("raised", "KeyError", ""),) * 3
    assert same["logs"] == [("error", "Userdata key 'k' not available. Available keys are: ['present']")] * 3


def const_scenario(side):
    """An input-only list, dict and object: lists and dicts come raw (mutable in place), an object
    with a __dict__ comes wrapped; setting an attribute on the wrapper is tried."""
    class Thing:
        def __init__(self):
            self.v = 1

    def body(ud):
        ud.items.append(3)
        ud.table["k"] = "v"
        thing = ud.thing
        return type(thing).__name__, thing.v, outcome_of(lambda: setattr(thing, "v", 2))
    built, got = run_one(side.sm, body, input_keys=["items", "table", "thing"])
    built.userdata.items = [1, 2]
    built.userdata.table = {}
    built.userdata.thing = Thing()
    outcome_of(built.execute)
    return got, built.userdata.items, built.userdata.table, built.userdata.thing.v


def test_input_only_values_are_raw_when_they_have_no_dict_and_wrapped_in_const_when_they_have_one(parity):
    """[bug] D33, documented: setting an attribute on the Const wrapper silently stores it on the
    wrapper in the original, fsm raises TypeError after logging (SMACH's own line for it). The wrapped
    value is unchanged on both."""
    theirs, ours = parity.run(const_scenario)
    assert theirs["result"] == ([("Const", 1, ("returned", None))], [1, 2, 3], {"k": "v"}, 1)
    assert ours["result"] == ([("Const", 1, ("raised", "TypeError", ""))], [1, 2, 3], {"k": "v"}, 1)
    refusal = ("error", "Attempting to set 'v' but this member is read-only.")
    assert refusal in ours["logs"]
    assert [line for line in ours["logs"] if line != refusal] == theirs["logs"]


def test_remapper_keys_documented_fix_lists_the_local_names(parity):
    """[bug] D34, documented: the original's Remapper.keys() misses remapped keys; fsm lists the
    local names of the input keys present. ``in`` agrees on both."""
    def scenario(side):
        built, got = run_one(side.sm, lambda ud: (sorted(ud.keys()), "local" in ud, "plain" in ud),
                             input_keys=["local", "plain"], remapping={"local": "parent"})
        built.userdata.parent = 1
        built.userdata.plain = 2
        outcome_of(built.execute)
        return got
    theirs, ours = parity.run(scenario)
    assert theirs["result"] == [(["plain"], True, True)]
    assert ours["result"] == [(["local", "plain"], True, True)]
    assert ours["logs"] == theirs["logs"]


def test_containers_copy_their_declared_keys_in_and_out_and_warn_about_missing_ones(parity):
    def scenario(side):
        k = kit(side.sm)
        seen = []
        sub = k.machine(["done"], [("LOOK", k.Out(lambda ud: seen.append(sorted(ud.keys())) or "done",
                                                  input_keys=["a", "b", "gone"]), {})],
                        input_keys=["a", "missing"], output_keys=["a", "absent"])
        blind = k.machine(["done"], [("LOOK", k.Out(lambda ud: seen.append("b" in ud) or "done", input_keys=["b"]), {})])
        root = k.machine(["done"], [("SUB", sub, {"done": "BLIND"}), ("BLIND", blind, {})])
        root.userdata.a = 1
        root.userdata.b = 2
        return outcome_of(root.execute), seen, sorted(root.userdata.keys())
    same = parity.same(scenario)
    assert same["result"] == (("returned", "done"), [["a"], False], ["a", "b"])
    assert ("warn", "Attempting to copy input key 'missing', but this key does not exist.") in same["logs"]
    assert ("warn", "Attempting to copy output key 'absent', but this key does not exist.") in same["logs"]


def test_key_arguments_given_as_tuples_raise_type_error_outcomes_take_any_iterable(parity):
    def scenario(side):
        sm = side.sm
        return (outcome_of(lambda: sm.State(["done"], input_keys=("x",))),
                outcome_of(lambda: sorted(sm.State(("a", "b")).get_registered_outcomes())))
    assert parity.same(scenario)["result"] == (
        ("raised", "TypeError", 'can only concatenate tuple (not "list") to tuple'), ("returned", ["a", "b"]))


def test_cb_interface_takes_no_io_keys_and_cbstate_merges_what_it_declares(parity):
    def scenario(side):
        sm = side.sm
        refused = outcome_of(lambda: sm.cb_interface(outcomes=["x"], io_keys=["k"]))

        @sm.cb_interface(outcomes=["extra"], input_keys=["i"], output_keys=["o"])
        def cb(ud, word):
            return word
        state = sm.CBState(cb, cb_args=["extra"], outcomes=["done"], input_keys=["own"])
        ud = sm.UserData()
        return (refused[:2], sorted(state.get_registered_outcomes()), sorted(state.get_registered_input_keys()),
                sorted(state.get_registered_output_keys()), state.execute(ud))
    assert parity.same(scenario)["result"] == (("raised", "TypeError"), ["done", "extra"], ["i", "own"], ["o"], "extra")


def test_userdata_update_merges_another_userdata(parity):
    def scenario(side):
        sm = side.sm
        ud, other = sm.UserData(), sm.UserData()
        ud.a, ud.b = 1, 2
        other.b, other.c = 20, 30
        ud.update(other)
        return sorted((key, ud[key]) for key in ud.keys())
    assert parity.same(scenario)["result"] == [("a", 1), ("b", 20), ("c", 30)]


def test_userdata_extract_and_merge_follow_the_remapping(parity):
    def scenario(side):
        sm = side.sm
        parent = sm.UserData()
        parent.p = [1]
        parent.q = 2
        local = parent.extract(["p", "q"], {"local_p": "p"})
        into = sm.UserData()
        into.merge(local, ["local_p"], {"local_p": "back"})
        not_one_to_one = outcome_of(lambda: parent.extract([], {"a": "p", "b": "p"}))
        return sorted(local.keys()), local.local_p == [1], local.local_p is parent.p, sorted(into.keys()), not_one_to_one[0]
    same = parity.same(scenario)
    assert same["result"] == (["local_p", "q"], True, False, ["back"], "returned")


def test_a_missing_key_read_by_a_state_fails_with_the_same_traceback_text(parity):
    def scenario(side):
        built, got = run_one(side.sm, lambda ud: ud.k, input_keys=["k"])
        return outcome_of(built.execute)
    same = parity.same(scenario)
    assert same["result"][2].endswith("KeyError: 'k'\n\nDuring handling of the above exception, another exception "
                                      "occurred:\n\nTraceback (most recent call last):\n  …\nKeyError\n")


def test_cb_interface_keeps_its_outcomes_in_the_order_given(parity):
    def scenario(side):
        @side.sm.cb_interface(outcomes=["z", "a", "m"], input_keys=["i"], output_keys=["o"])
        def cb(ud):
            return "z"
        return cb.get_registered_outcomes(), cb.get_registered_input_keys(), cb.get_registered_output_keys()
    assert parity.same(scenario)["result"] == (("z", "a", "m"), ("i",), ("o",))


def test_cbinterface_io_keys_deliberate_fix(parity):
    """Fixed in fsm (fsm/core/util.py says so; not in README's table, listed in the parity report):
    the original's CBInterface drops its io_keys (a set union whose result is thrown away)."""
    def scenario(side):
        cb = side.sm.CBInterface(lambda ud: "x", outcomes=["x"], io_keys=["io"])
        return cb.get_registered_input_keys(), cb.get_registered_output_keys()
    theirs, ours = parity.run(scenario)
    assert theirs["result"] == ((), ())
    assert ours["result"] == (("io",), ("io",))


def test_an_item_key_with_a_leading_underscore_is_stored_as_a_key(parity):
    def scenario(side):
        ud = side.sm.UserData()
        ud["_x"] = 1
        other = side.sm.UserData()
        other.update(ud)
        return ud.keys(), other.keys(), outcome_of(lambda: ud["_x"])[:2]
    assert parity.same(scenario)["result"] == (["_x"], ["_x"], ("raised", "AttributeError"))


def test_printing_userdata_or_a_const_undocumented_difference(parity):
    """Not in README's table (listed in the parity report): fsm prints a UserData as its dict and a
    Const as the value it wraps; the original prints both as objects."""
    def scenario(side):
        class Thing:
            def __str__(self):
                return "thing"
        ud = side.sm.UserData()
        ud.a = 1
        ud.thing = Thing()
        return str(ud), str(side.sm.Remapper(ud, ["thing"], [], {}).thing)
    theirs, ours = parity.run(scenario)
    assert theirs["result"] == ("<smach.user_data.UserData object at 0x…>", "<smach.user_data.Const object at 0x…>")
    assert ours["result"][1] == "thing"
    assert ours["result"][0].startswith("{'a': 1, 'thing': <")


def test_a_method_of_an_input_only_object_documented_fix(parity):
    """[bug] D33, documented: the original wraps a bound method in Const too, so it cannot be called;
    fsm returns callables as they are."""
    def scenario(side):
        class Thing:
            def speak(self):
                return "spoken"
        built, got = run_one(side.sm, lambda ud: outcome_of(lambda: ud.thing.speak()), input_keys=["thing"])
        built.userdata.thing = Thing()
        outcome_of(built.execute)
        return got
    theirs, ours = parity.run(scenario)
    assert theirs["result"] == [("raised", "TypeError", "'Const' object is not callable")]
    assert ours["result"] == [("returned", "spoken")]
