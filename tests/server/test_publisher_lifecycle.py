"""A machine published from another process (README's `smach.attach(sm, Publisher(url, token))`):
its last events arrive even when the script exits at once, and a publisher that goes away in the
middle of a run shows its machine disconnected, not running."""

from __future__ import annotations

import signal

from publishing_support import publish, remote
from fsmscope.server.testing.polling import wait_for


def test_a_script_that_exits_right_after_its_run_delivers_the_last_events(live_server, tmp_path):
    proc = publish(tmp_path, live_server, 0.0)
    assert proc.wait(30) == 0
    wait_for(lambda: remote(live_server) is not None and remote(live_server)["outcome"] == "done", timeout=5)
    assert remote(live_server)["running"] is False


def test_a_publisher_killed_mid_run_shows_its_machine_disconnected_not_running(live_server, tmp_path):
    proc = publish(tmp_path, live_server, 30.0)
    try:
        assert proc.stderr.readline().strip() == "started"
        wait_for(lambda: remote(live_server) is not None and remote(live_server)["running"], timeout=10)
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait(10)
    wait_for(lambda: remote(live_server)["connected"] is False, timeout=10)
    info = remote(live_server)
    assert info["running"] is False and info["outcome"] is None
