"""A ROS 1 bag of a SMACH run, one command (`fsmscope replay BAG --serve`), the run in the dashboard."""

from __future__ import annotations

from bag_support import GRASP, PLACE, ROOT, write_bag
from recording_support import replay_served

from fsm.observation.schema import container_id, state_id
from fsmscope.server.testing.browser import open_page
from fsmscope.server.testing.polling import wait_for


def test_a_ros1_bag_replayed_shows_its_run_in_the_dashboard(browser, tmp_path):
    bag = write_bag(tmp_path / "pick_place.bag", "ros1")
    with replay_served(bag) as (url, _):
        page = open_page(browser, url + "#m=pick_place&seq=14")
        try:
            page.wait_for_selector("#graph svg")
            wait_for(lambda: page.evaluate("fsmscope.instant.seq") == 14, 10, what="the run's last event shown")
            ids = page.eval_on_selector_all("#graph g[id]", "gs => gs.map((g) => g.id)")
            assert {state_id(ROOT + "/FIND"), container_id(GRASP), container_id(PLACE)} <= set(ids)
            root = page.evaluate("fsmscope.status.containers[%r]" % ROOT)
            assert root["outcome"] == "succeeded" and not root["running"]
            assert not page.errors
        finally:
            page.close()
