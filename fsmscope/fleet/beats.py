"""A dashboard's heartbeats to the robots whose machines it leases: every ``BEAT`` seconds a counter,
put on ``fsmscope-dashboards/<session>/<robot>`` with its proof of that robot's token. The robot
takes a beat only when it proves the token and its counter is higher than the last one's
(fsmscope/fleet/control.py): a stranger can neither forge a beat nor keep a dead dashboard's lease alive by
playing its beats again, as a liveliness token anyone may declare could."""

from __future__ import annotations

import itertools
import threading

import zenoh

from . import keys, proofs
from .control import BEAT


class Heartbeats:
    """Beats for each robot this dashboard has told of a lease, until it closes."""

    def __init__(self, session: zenoh.Session, dashboard: str) -> None:
        self.session = session
        self.dashboard = dashboard
        self._robots: dict[str, str] = {}  # robot: its token
        self._counter = itertools.count(1)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="fsmscope-fleet-beats", daemon=True)
        self._thread.start()

    def keep(self, robot: str, token: str) -> None:
        """Beat for ``robot`` from now on (one at once: the lease it was just told counts from now)."""
        self._robots[robot] = token
        self._beat(robot, token)

    def close(self) -> None:
        self._stop.set()
        if self._thread is not threading.current_thread():
            self._thread.join(BEAT * 4)

    def _run(self) -> None:
        while not self._stop.wait(BEAT):
            for robot, token in list(self._robots.items()):
                self._beat(robot, token)

    def _beat(self, robot: str, token: str) -> None:
        key = keys.beat_key(self.dashboard, robot)
        payload = str(next(self._counter)).encode()
        try:
            self.session.put(key, payload, attachment=proofs.sign(token, b"beat", key, payload))
        except zenoh.ZError:  # the session closed
            self._stop.set()
