"""The timeline component (fsmscope/static/timeline.js) in the served dashboard page, on a host element of its
own with synthetic /timeline data: what the user's drags, clicks, wheel and keys ask of the page, the
"back to live" control, and names drawn as text."""

from __future__ import annotations

import fsm
import pytest
from browser_support import served_page
from smach_support import Out, one_state_machine

T0 = 1_700_000_000.0  # the run's first event
SPAN = 100.0  # seconds to its last
MARKUP = "<img src=x onerror=window.pwned=1>"


def timeline_data(inner: str = "SUB", label: str = "X") -> dict:
    """A run of 100 s: /SM_ROOT in A then ``inner``; /SM_ROOT/``inner`` in ``label`` then many states;
    an error at 60 s (seq 66)."""
    sub = "/SM_ROOT/" + inner
    return {
        "first": {"seq": 1, "t": T0}, "last": {"seq": 120, "t": T0 + SPAN}, "kept_from": 1,
        "runs": [{"run": 1, "seq": 1, "t": T0}],
        "bands": {
            "/SM_ROOT": [[T0, T0 + 40, 1, "A"], [T0 + 40, T0 + SPAN, 50, inner]],
            sub: [[T0, T0 + 40, 1, None], [T0 + 40, T0 + 70, 50, label], [T0 + 70, T0 + SPAN, 80, "…"]],
        },
        "ticks": [{"seq": 66, "t": T0 + 60, "kind": "error", "text": "boom"},
                  {"seq": 90, "t": T0 + 85, "kind": "control", "text": "pause"}],
        "transitions": [[1, T0], [50, T0 + 40], [80, T0 + 70]],
        "coarse": False,
    }


# Builds a Timeline on a fresh host under the page's layout; window.calls records what it asks.
BUILD = """async ([data, instant]) => {
    const { Timeline } = await import('/timeline.js');
    window.tl?.destroy();
    document.getElementById('tl-test')?.remove();
    const host = Object.assign(document.createElement('section'), { id: 'tl-test', className: 'timeline-pane' });
    document.body.append(host);
    window.calls = [];
    const record = (name) => (...args) => window.calls.push([name, ...args]);
    window.tl = new Timeline(host, Object.fromEntries(
        ['seek', 'range', 'play', 'pause', 'speed', 'step', 'live'].map((name) => [name, record(name)])));
    tl.setData(data);
    tl.setInstant(instant);
    await new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done)));
}"""


@pytest.fixture(scope="module")
def page(browser):  # noqa: F811
    fsm.set_loggers(*(lambda msg: None,) * 4)
    with served_page(browser, one_state_machine("A", Out()), "timeline") as page:
        yield page


def build(page, data: dict | None = None, **instant) -> None:
    instant = {"seq": 120, "t": T0 + SPAN, "live": False, **instant}
    page.evaluate(BUILD, [data or timeline_data(), instant])


def calls(page, name: str) -> list:
    """The arguments of each call of handler ``name`` so far, once there is one."""
    page.wait_for_function("name => calls.some((c) => c[0] === name)", arg=name)
    return [c[1:] for c in page.evaluate("calls") if c[0] == name]


def point(page, t: float, y: float) -> tuple[float, float]:
    """Where time ``t`` is on the timeline's canvas (whole run shown), ``y`` px from its top, in page pixels."""
    box = page.locator("#tl-test canvas").bounding_box()
    x = page.evaluate("""async ([t, w, v0, v1]) => {
        const { xOf } = await import('/timeline_draw.js');
        return xOf({ w, v0, v1 }, t);
    }""", [t, box["width"], T0, T0 + SPAN])
    return box["x"] + x, box["y"] + y


AXIS_Y, MARKS_Y, FIRST_ROW_Y, SECOND_ROW_Y = 11, 30, 47, 65


def test_a_drag_on_the_axis_seeks_the_time_under_the_pointer(page):
    build(page)
    page.mouse.move(*point(page, T0 + 10, AXIS_Y))
    page.mouse.down()
    page.mouse.move(*point(page, T0 + 30, AXIS_Y), steps=5)
    page.mouse.up()
    last = calls(page, "seek")[-1][0]
    assert last["t"] == pytest.approx(T0 + 30, abs=0.5)


def test_a_click_on_an_error_tick_seeks_its_event(page):
    build(page)
    page.mouse.click(*point(page, T0 + 60, MARKS_Y))
    assert calls(page, "seek") == [[{"seq": 66}]]


def test_a_click_on_a_band_seeks_its_first_event(page):
    build(page)
    page.mouse.click(*point(page, T0 + 55, SECOND_ROW_Y))
    assert calls(page, "seek") == [[{"seq": 50}]]


def test_the_wheel_over_the_bands_zooms_into_a_narrower_range(page):
    build(page)
    page.mouse.move(*point(page, T0 + 50, FIRST_ROW_Y))
    page.mouse.wheel(0, -300)
    [[asked]] = calls(page, "range")
    assert T0 < asked["since_t"] < T0 + 50 < asked["until_t"] < T0 + SPAN


def test_right_arrow_steps_to_the_next_transition_of_any_container(page):
    build(page)
    page.keyboard.press("ArrowRight")
    assert calls(page, "step") == [[1, None]]


def test_shift_right_steps_to_the_next_transition_of_the_selected_rows_container(page):
    build(page)
    page.mouse.click(page.locator("#tl-test canvas").bounding_box()["x"] + 40, point(page, T0, SECOND_ROW_Y)[1])
    page.keyboard.press("Shift+ArrowRight")
    assert calls(page, "step") == [[1, "/SM_ROOT/SUB"]]


@pytest.mark.parametrize("instant, shown", [
    ({"live": False, "behind": 7, "liveMachine": True}, True),
    ({"live": True, "liveMachine": True}, False),
    ({"live": False, "behind": 7, "liveMachine": False}, False),
], ids=["looking back at a live machine", "live", "a replay"])
def test_back_to_live_shows_only_when_looking_back_at_a_live_machine(page, instant, shown):
    build(page, **instant)
    assert page.is_visible("#tl-test button:has-text('back to live')") is shown


def test_names_with_markup_are_drawn_as_text(page):
    build(page, timeline_data(inner=MARKUP, label=MARKUP))
    page.mouse.move(*point(page, T0 + 55, SECOND_ROW_Y))
    page.wait_for_function("text => document.querySelector('#tl-test canvas').title.includes(text)", arg=MARKUP)
    assert page.evaluate("document.querySelectorAll('img').length") == 0
    assert page.evaluate("window.pwned") is None


def test_choosing_a_speed_asks_the_page_for_it(page):
    build(page)
    page.select_option("#tl-test select", "2")
    assert calls(page, "speed") == [[2]]


def test_a_speed_the_page_shows_is_selected_even_when_not_a_choice(page):
    build(page)
    page.evaluate("tl.showSpeed(3)")
    assert page.input_value("#tl-test select") == "3"


def test_a_history_that_no_longer_reaches_the_first_event_says_how_far_back_it_reaches(page):
    data = {**timeline_data(), "first": {"seq": 40, "t": T0}, "kept_from": 60}
    build(page, data)
    assert page.text_content("#tl-test .tl-kept") == (
        "history reaches back to %s (seq 40); full detail from seq 60" % page.evaluate(
            "async (t) => (await import('/clocktext.js')).clockText(t)", T0))


def test_the_status_line_says_how_far_behind_the_past_shown_is(page):
    build(page, behind=7, liveMachine=True)
    assert page.text_content("#tl-test .tl-status") == "viewing the past: %s, 7 events behind" % page.evaluate(
        "async (t) => (await import('/clocktext.js')).clockText(t)", T0 + SPAN)
