"""Which containers the graph draws open (fsmscope/static/depth.js): the depth selector and a double-click on
one container. A closed container is drawn as one node (s:PATH), an open one as a cluster (c:PATH)."""

from __future__ import annotations

import pytest
from browser_support import watching
from fsm.observation.schema import container_id, state_id
from fsmscope.server.http_server import ServerThread
from server_support import nested_machine

SUB = "/SM_ROOT/SUB"


@pytest.fixture(scope="module")
def served():
    """A server with `nested` (SM_ROOT: SUB(A -> B) -> C), never run."""
    srv = ServerThread().start()
    srv.hub.add_local(nested_machine(), name="nested")
    yield srv
    srv.stop()


@pytest.fixture
def page(browser, served):
    with watching(browser, served, "nested") as page:
        yield page


def drawn(page, element_id: str) -> None:
    page.wait_for_selector('#graph svg [id="%s"]' % element_id, state="attached")


def test_by_default_the_server_draws_the_nested_machine_open(page):
    drawn(page, container_id(SUB))
    assert page.input_value("#depth") == "auto"


def test_depth_one_draws_the_nested_machine_closed(page):
    page.select_option("#depth", "1")
    drawn(page, state_id(SUB))
    assert page.locator('#graph [id="%s"]' % container_id(SUB)).count() == 0


def test_double_clicking_a_closed_container_opens_it_and_the_depth_says_custom(page):
    page.select_option("#depth", "1")
    drawn(page, state_id(SUB))
    page.dblclick('#graph [id="%s"]' % state_id(SUB))
    drawn(page, container_id(SUB))
    assert page.input_value("#depth") == "custom"
