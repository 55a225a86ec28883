"""fsm.debugging.condition: a breakpoint's condition is parsed and walked, never given to eval."""

import pytest
from hypothesis import given, strategies as st

from fsm.debugging.condition import MAX_LENGTH, Condition, ConditionError


def holds(text, **userdata):
    return Condition(text).evaluate(lambda key: userdata[key])


@pytest.mark.parametrize("text, userdata, expected", [
    ("attempts > 2", {"attempts": 3}, True),
    ("attempts > 2", {"attempts": 2}, False),
    ("1 < attempts <= 3", {"attempts": 3}, True),
    ("'cube' in seen and not done", {"seen": ["cube"], "done": False}, True),
    ("len(queue) == 0 or attempts - 1 >= 4", {"queue": [1], "attempts": 5}, True),
    ("pose['z'] < 0.1", {"pose": {"z": 0.05}}, True),
    ("items[-1] == 'b'", {"items": ["a", "b"]}, True),
    ("target is None", {"target": None}, True),
    ("name not in ('A', 'B')", {"name": "C"}, True),
    ("-x == y + 1", {"x": -3, "y": 2}, True),
])
def test_a_condition_evaluates_over_userdata_keys(text, userdata, expected):
    assert holds(text, **userdata) is expected


@pytest.mark.parametrize("text, words", [
    ("__import__('os').system('touch /tmp/pwned')", "a call other than len(...) is not allowed (column 1)"),
    ("open('/etc/passwd')", "a call other than len(...) is not allowed (column 1)"),
    ("x.__class__", "an attribute ('.') is not allowed (column 2)"),
    ("(lambda: 1)()", "a call other than len(...) is not allowed"),
    ("x ** 999999", "this operator (only + and -) is not allowed (column 3)"),
    ("'a' * 10", "this operator (only + and -) is not allowed"),
    ("[y for y in x]", "a comprehension is not allowed"),
    ("__builtins__", "a name beginning with '__' is not allowed (column 1)"),
    ("x[1:2]", "an index must be a literal"),
    ("attempts >", "not a condition: invalid syntax"),
    ("", "a condition must be a non-empty text"),
])
def test_a_condition_beyond_the_small_language_is_refused_saying_what_and_where(text, words):
    with pytest.raises(ConditionError) as info:
        Condition(text)
    assert words in str(info.value)


def test_refused_text_is_never_run(tmp_path):
    marker = tmp_path / "ran"
    with pytest.raises(ConditionError):
        Condition("__import__('pathlib').Path(%r).touch()" % str(marker))
    assert not marker.exists()


def test_a_syntax_error_names_its_column():
    with pytest.raises(ConditionError) as info:
        Condition("attempts > > 2")
    assert info.value.column == 12


@pytest.mark.parametrize("text, column", [
    ("attempts >> 1", 10),
    ("attempts > 1 and n ** 2 > 4", 20),
    ("(attempts) * 2", 12),
    ("pose.z < 0.1", 5),
    ("name == 'é' and attempts // 2", 26),
    ("  attempts >> 1", 12),
    ("items[n] == 1", 7),
])
def test_a_refusal_names_the_column_of_the_part_refused_not_where_its_expression_begins(text, column):
    with pytest.raises(ConditionError) as info:
        Condition(text)
    assert info.value.column == column


def test_a_syntax_error_python_places_before_the_text_names_its_first_column():
    with pytest.raises(ConditionError) as info:
        Condition("+")
    assert info.value.column == 1


def test_a_missing_key_is_an_error_that_names_it():
    with pytest.raises(ConditionError, match="there is no userdata key 'attempts'"):
        holds("attempts > 2")


def test_an_operation_that_fails_on_the_values_is_an_error_that_says_so():
    with pytest.raises(ConditionError, match="TypeError"):
        holds("x > 2", x="text")


def test_a_condition_longer_than_the_bound_is_refused():
    with pytest.raises(ConditionError, match="at most %d characters" % MAX_LENGTH):
        Condition(" or ".join(["x"] * MAX_LENGTH))


def test_a_condition_lists_the_keys_it_reads():
    assert Condition("len(queue) > attempts and done").keys == ["attempts", "done", "queue"]


@given(st.integers(), st.integers())
def test_comparisons_agree_with_python(a, b):
    for op in ("<", "<=", ">", ">=", "==", "!="):
        assert holds("a %s b" % op, a=a, b=b) == {"<": a < b, "<=": a <= b, ">": a > b, ">=": a >= b,
                                                  "==": a == b, "!=": a != b}[op]


@given(st.text(max_size=60))
def test_any_text_is_either_a_condition_or_a_condition_error(text):
    try:
        condition = Condition(text)
    except ConditionError:
        return
    try:
        condition.evaluate(lambda key: 1)
    except ConditionError:
        pass
