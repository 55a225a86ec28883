"""Machines published from another process (``smach.attach(sm, Publisher(url, token))``), for the
server's and the browser's tests: a script that runs once (``publish``), and one that loops and takes
the dashboard's controls (``Published``, the ``published`` fixture)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import pytest
from browser_support import ROOT
from fsmscope.server.testing.polling import wait_for
from server_support import client

ONCE_SCRIPT = textwrap.dedent("""
    import sys, time
    import fsm as smach
    from fsmscope.server.publisher import Publisher

    def step(ud):
        time.sleep(float(sys.argv[3]))
        return "go"

    sm = smach.StateMachine(outcomes=["done"])
    with sm:
        smach.StateMachine.add("A", smach.CBState(step, outcomes=["go"]), {"go": "B"})
        smach.StateMachine.add("B", smach.CBState(step, outcomes=["go"]), {"go": "done"})
    smach.attach(sm, Publisher(sys.argv[1], sys.argv[2]), name="remote")
    print("started", file=sys.stderr, flush=True)
    sm.execute()
""")


def publish(tmp_path, srv, step_seconds: float) -> subprocess.Popen:
    script = tmp_path / "publish.py"
    script.write_text(ONCE_SCRIPT)
    return subprocess.Popen([sys.executable, str(script), srv.base_url, srv.token, str(step_seconds)], cwd=ROOT,
                            stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True, env=dict(os.environ, PYTHONPATH=str(ROOT)))


def remote(srv) -> dict | None:
    return next((m for m in client(srv).get("/api/machines").json() if m["name"] == "remote"), None)


LOOP_SCRIPT = textwrap.dedent("""
    import sys, time
    import fsm as smach
    from fsmscope.server.publisher import Publisher

    class Tick(smach.State):
        # Counts in userdata n; services a preempt; 'stop' only when forced.
        def __init__(self):
            smach.State.__init__(self, outcomes=["go", "stop", "preempted"], input_keys=["n"], output_keys=["n"])

        def execute(self, ud):
            time.sleep(0.005)
            ud.n = ud.n + 1
            if self.preempt_requested():
                self.service_preempt()
                return "preempted"
            return "go"

    smach.set_loggers(*[lambda msg: None] * 4)
    sm = smach.StateMachine(outcomes=["done", "preempted"])
    sm.userdata.n = 0
    with sm:
        smach.StateMachine.add("A", Tick(), {"go": "B", "stop": "done", "preempted": "preempted"})
        smach.StateMachine.add("B", Tick(), {"go": "A", "stop": "done", "preempted": "preempted"})
    smach.attach(sm, smach.Recorder(sys.argv[3]), name="remote")
    smach.attach(sm, Publisher(sys.argv[1], sys.argv[2], backoff_max=0.2))
    sm.execute()
""")


class Published:
    """The publishing subprocess, its machine's name on the server and its own recording."""

    def __init__(self, srv, tmp_path) -> None:
        script = tmp_path / "publish.py"
        script.write_text(LOOP_SCRIPT)
        self.log = tmp_path / "remote.jsonl"
        self.srv = srv
        self.http = client(srv)
        self.proc = subprocess.Popen([sys.executable, str(script), srv.base_url, srv.token, str(self.log)], cwd=ROOT,
                                     stdout=subprocess.DEVNULL, env=dict(os.environ, PYTHONPATH=str(ROOT)))

    def info(self) -> dict | None:
        return next((m for m in self.http.get("/api/machines").json() if m["name"] == "remote"), None)

    def status(self) -> dict:
        return self.http.get("/api/machines/remote/status").json()

    def holds(self) -> list[dict]:
        return self.status()["debug"]["holds"]

    def own_events(self) -> list[dict]:
        """The events the publishing process recorded itself (its Recorder's log)."""
        if not self.log.exists():
            return []
        return [json.loads(line) for line in self.log.read_text().splitlines() if line.endswith("}")]


@pytest.fixture
def published(live_server, tmp_path):
    pub = Published(live_server, tmp_path)
    try:
        wait_for(lambda: (pub.info() or {}).get("running"), timeout=15, what="the published machine running")
        yield pub
    finally:
        pub.proc.kill()
        pub.proc.wait(10)
