"""Where a hub's machine comes from, as the routes and the overview show it: ``source`` (local: this
process runs it; ingest: another process publishes it, over /api/ingest or Zenoh; replay: a log),
whether that process is connected, a fleet machine's robot, a replay's play speed, and the events
refused at the door. The door a machine comes through owns its origin: the hub's ``add_local`` and
``ingest``, the ingest link (fsmscope/server/remote_control.py), the fleet bridge and the replay (fsmscope/server/cli/).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class Origin:
    source: str  # local, ingest or replay (fsm.observation.schema.SOURCES)
    connected: bool | None = None  # another process's: whether its publisher is connected (None: not another's)
    robot: str | None = None  # a fleet machine's robot (its name is "<robot>:<machine>")
    replay: dict | None = None  # replayed from a log: {"speed": the page's initial play speed}
    rejected: int = 0  # events refused at the door (ingest) for not fitting the schema
    script: str | None = None  # a machine of `fsmscope run`: the script that built it (a page follows its newest)

    @property
    def gone(self) -> bool:
        """The process that publishes it went away."""
        return self.connected is False
