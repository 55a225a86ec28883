"""The demo page as a user sees it: `fsmscope demo` as a real process (shared with the demo's other
tests), Debian's Chromium."""

from __future__ import annotations

import io

import pytest
from browser_support import ACTIVE_LEAF
from demo_support import watching_demo
from fsmscope.server.testing.polling import wait_for

# The arm's links are orange in fsmscope/sim/arm.xml (rgba 0.85 0.55 0.20); lit and shaded they stay
# clearly red > green > blue.
def is_arm_orange(r: int, g: int, b: int) -> bool:
    return r > 120 and r - b > 90 and r > g > b and g - b > 25



@pytest.fixture(scope="module")
def page(browser, shared_demo):
    """The shared demo, watched with its 3D view (its tests only look)."""
    with watching_demo(browser, shared_demo, scene=True) as page:
        yield page


@pytest.mark.timeout(90)
def test_demo_page_draws_the_arm_in_the_3d_view(page):
    page.wait_for_selector("#scene-pane:not([hidden]) iframe")
    scene = page.frame_locator("#scene-pane iframe")
    scene.locator("canvas").first.wait_for(state="visible")
    from PIL import Image

    def many_orange_pixels() -> int:
        shot = Image.open(io.BytesIO(page.locator("#scene-pane .scene").screenshot())).convert("RGB")
        orange = sum(1 for pixel in shot.get_flattened_data() if is_arm_orange(*pixel))
        return orange if orange > 200 else 0

    orange = wait_for(many_orange_pixels, 30, interval=1.0, what="arm-coloured pixels in the 3D view")
    assert orange > 200, "no arm-coloured pixels in the 3D view"


@pytest.mark.timeout(90)
def test_demo_graph_highlights_the_running_state_as_the_arm_moves(page):
    seen = set()

    def three_seen() -> bool:
        seen.add(page.evaluate(ACTIVE_LEAF))
        seen.discard(None)  # between two episodes nothing is active
        return len(seen) >= 3

    wait_for(three_seen, 30, interval=0.2, what=lambda: "three active states; seen %r" % seen)
    assert all(node.startswith("s:/SM_ROOT/") for node in seen)
