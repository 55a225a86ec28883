"""The search palette (fsmscope/static/search.js, search_index.js) and the details of the selected state
(fsmscope/static/details.js) on a generated machine of several hundred states (fsmscope/server/testing/big_machine.py)
whose container names carry markup, in Chromium."""

from __future__ import annotations


import pytest
from browser_support import serving_while_running, watching
from fsm.observation.schema import container_id, state_id
from fsmscope.server.testing.big_machine import big_machine, count_states
from fsmscope.server.testing.polling import wait_for

MARKUP = "<img src=x onerror=window.__xss=1>T"  # the prefix of every container's name
BRANCHING, DEPTH, LEAVES = 3, 4, 8  # 360 states: the server's default draws only the root open
DEEP = "/SM_ROOT/{m}_1/{m}_1_2/{m}_1_2_0/W_1_2_0_3".format(m=MARKUP)
DEEP_LABEL = "W_1_2_0_3"


@pytest.fixture(scope="module")
def served():
    """A server showing 'big' while it runs (a leaf every 20 ms), stopped at the end."""
    sm, stop = big_machine(BRANCHING, DEPTH, LEAVES, tick=0.02, names=MARKUP)
    with serving_while_running(sm, stop, "big") as srv:
        yield srv


@pytest.fixture
def page(browser, served):
    with watching(browser, served, "big") as page:
        yield page


def search(page, text: str) -> None:
    """Open the palette with Ctrl-K and type ``text``."""
    page.keyboard.press("Control+k")
    page.wait_for_selector("#search-dialog[open]")
    page.fill("#search-dialog input", text)


def choose(page, text: str) -> None:
    """Search ``text`` and take the best result with Enter."""
    search(page, text)
    page.wait_for_selector("#search-dialog li[aria-selected=true]")
    page.keyboard.press("Enter")


def in_view(page, element_id: str) -> bool:
    """Whether the graph draws ``element_id`` inside the graph pane's visible area."""
    return page.evaluate("""(id) => {
        const el = document.getElementById(id), view = document.getElementById('graph').getBoundingClientRect();
        if (!el) return false;
        const b = el.getBoundingClientRect();
        return b.width > 0 && b.left >= view.left && b.right <= view.right && b.top >= view.top && b.bottom <= view.bottom;
    }""", element_id)


def test_the_machine_is_big_enough_that_the_deep_state_starts_hidden(page):
    assert count_states(BRANCHING, DEPTH, LEAVES) >= 300
    assert page.locator('#graph [id="%s"]' % state_id(DEEP)).count() == 0


def test_choosing_a_deep_state_opens_the_containers_on_its_path(page):
    choose(page, DEEP_LABEL)
    page.wait_for_selector('#graph [id="%s"]' % state_id(DEEP), state="attached")
    parent = DEEP.rsplit("/", 1)[0]
    assert page.locator('#graph [id="%s"]' % container_id(parent)).count() == 1


def test_choosing_a_deep_state_brings_it_into_view(page):
    choose(page, DEEP_LABEL)
    page.wait_for_selector('#graph [id="%s"]' % state_id(DEEP), state="attached")
    wait_for(lambda: in_view(page, state_id(DEEP)), timeout=10, what=lambda: "the chosen state in view; " + page.evaluate(
        """(id) => {
          const el = document.getElementById(id), view = document.getElementById('graph').getBoundingClientRect();
          const b = el && el.getBoundingClientRect();
          return JSON.stringify({ drawn: Boolean(el), box: b && [b.left, b.top, b.right, b.bottom],
            graph: [view.left, view.top, view.right, view.bottom], selected: window.fsmscope.selected,
            follow: document.getElementById('follow').checked, depth: document.getElementById('depth').value });
        }""", state_id(DEEP)))


def test_choosing_a_state_selects_it(page):
    choose(page, DEEP_LABEL)
    wait_for(lambda: page.evaluate("window.fsmscope.selected") == DEEP, timeout=5, what="the state selected")


def test_arrow_keys_move_the_choice_and_enter_takes_it(page):
    search(page, "W_1_2_0_")
    page.keyboard.press("ArrowDown")
    page.keyboard.press("ArrowDown")
    wanted = page.locator("#search-dialog li[aria-selected=true] .search-path").text_content()
    page.keyboard.press("Enter")
    wait_for(lambda: page.evaluate("window.fsmscope.selected") == wanted.rsplit(" (", 1)[0], timeout=5,
             what="the third result selected")


def test_escape_closes_the_palette(page):
    search(page, "W_")
    page.keyboard.press("Escape")
    page.wait_for_selector("#search-dialog", state="hidden")


def test_slash_opens_the_palette(page):
    page.click("#graph")
    page.keyboard.press("/")
    page.wait_for_selector("#search-dialog[open]")


def test_a_userdata_key_shows_its_container_s_userdata(page):
    container = "/SM_ROOT/%s_2" % MARKUP
    wait_for(lambda: page.evaluate("(p) => 'visits' in (window.fsmscope.status.containers[p]?.userdata || {})",
                                   container), timeout=10, what="the container ran")
    search(page, "visits")
    page.locator("#search-dialog li.key", has_text="userdata of %s" % container).first.click()
    wait_for(lambda: page.input_value("#ud-container") == container, timeout=5, what="its userdata shown")


def test_an_outcome_selects_its_state(page):
    search(page, "stopped")
    row = page.locator("#search-dialog li.outcome").nth(3)
    state = row.locator(".search-path").text_content().removeprefix("of ")
    row.click()
    wait_for(lambda: page.evaluate("window.fsmscope.selected") == state, timeout=5, what="the outcome's state selected")


def test_at_most_fifty_results_are_shown(page):
    search(page, "W")
    page.wait_for_selector("#search-dialog li")
    assert page.locator("#search-dialog li").count() == 50
    assert "the best 50 shown" in page.text_content("#search-dialog .search-count")


def test_an_exact_name_ranks_before_a_longer_one(page):
    search(page, "w_1_2_0_3")
    first = page.locator("#search-dialog li .search-name").first.text_content()
    assert first == DEEP_LABEL


def test_a_fuzzy_subsequence_of_the_path_matches(page):
    search(page, "w1203")
    page.wait_for_selector("#search-dialog li")
    names = page.locator("#search-dialog li .search-name").all_text_contents()
    assert DEEP_LABEL in names


def test_markup_in_names_shows_as_text_in_the_results(page):
    search(page, "img src")
    page.wait_for_selector("#search-dialog li.container")
    assert page.locator("#search-dialog li.container .search-name").first.text_content().startswith(MARKUP)
    assert page.locator("#search-dialog img").count() == 0


def test_markup_in_names_never_executes(page):
    choose(page, MARKUP + "_1")
    page.click("#details > summary")
    page.wait_for_selector("#details .details-head")
    page.wait_for_timeout(300)  # an <img src=x> would have failed to load and run its onerror by now
    assert page.evaluate("window.__xss") is None
    assert page.locator("#tree img, #details img, #userdata img, #graph img").count() == 0


def test_details_show_the_keys_and_their_remapping(page):
    choose(page, DEEP_LABEL)
    page.click("#details > summary")
    page.wait_for_selector("#details .details-keys")
    assert "count ⇄ container's visits" in page.locator("#details .details-keys").first.text_content()


def test_details_show_where_each_outcome_leads(page):
    choose(page, DEEP_LABEL)
    page.click("#details > summary")
    page.wait_for_selector("#details .details-outcomes")
    text = page.locator("#details .details-outcomes").text_content()
    assert "done → W_1_2_0_4" in text and "stopped" in text


def test_details_show_the_class_and_its_docstring(page):
    choose(page, DEEP_LABEL)
    page.click("#details > summary")
    page.wait_for_selector("#details .details-doc")
    assert page.text_content("#details .details-head") == DEEP_LABEL + " Work"
    assert page.text_content("#details .details-doc").startswith("One unit of a task")


def test_details_show_the_visits_counted_by_the_server(page):
    choose(page, "W_0")
    page.click("#details > summary")
    wait_for(lambda: page.text_content("#details .details-visits") not in (None, "0"), timeout=10,
             what="visits of /SM_ROOT/W_0")
    assert page.text_content("#details .details-last-outcome") == "done"
