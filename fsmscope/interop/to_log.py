"""Events read from another format (a ROS bag's SMACH runs, an MCAP file) written as fsmscope's own
log (the recorder's JSON Lines, with its snapshots and index), so that replay, the dashboard, time
travel and export work on them unchanged."""

from __future__ import annotations

import os
from typing import Callable, Iterable

from fsm.logfiles.recorder import Recorder, index_path
from fsm.observation.schema import validate


class ReadError(Exception):
    """The source cannot be read; the message says why."""


class NotWritten(Exception):
    """The log cannot be written (a full disk); no file is left. The message says why."""


class Damaged(ReadError):
    """The source is damaged part way: ``written`` events came before the damage, and were kept."""

    def __init__(self, message: str, written: int) -> None:
        super().__init__(message)
        self.written = written


class NoEvents(ReadError):
    """Not one event of the source fits the schema (or it has none): no log is written."""


def write_log(events: Iterable[dict], log: str, skipped: Callable[[str], None] | None = None) -> int:
    """``events`` into a new file ``log``; the number written. Each event is checked by the schema's
    validator first, as replay checks each line (fsm.observation.schema.validate): one it refuses is
    not written (``skipped`` hears why), so that a log imported is one replay reads whole. Raises
    ``ReadError`` (from the source) when nothing can be read, ``NoEvents`` when no event fits (no file
    is left then), ``Damaged`` when part can be read, ``NotWritten`` when the log cannot be written
    whole (no file is left)."""
    if os.path.exists(log):
        raise ReadError("%s exists already: a new log is written" % log)
    written = refused = 0
    damage = None
    partial = log + ".partial"
    try:
        with Recorder(partial) as recorder:
            try:
                for event in events:
                    problem = validate(event)
                    if problem is not None:
                        refused += 1
                        if skipped is not None:
                            skipped("an event that does not fit the schema: %s" % problem)
                        continue
                    recorder(event)
                    written += 1
            except ReadError as exc:
                if not written:
                    raise
                damage = Damaged(str(exc), written)
        if recorder.failure is not None:
            raise NotWritten("%s not written: %s" % (log, recorder.failure.strerror or recorder.failure))
        if not written:
            raise NoEvents("no events%s" % (" (%d refused)" % refused if refused else ""))
    except BaseException:
        for path in (partial, index_path(partial)):
            if os.path.exists(path):
                os.remove(path)
        raise
    os.replace(partial, log)
    os.replace(index_path(partial), index_path(log))
    if damage is not None:
        raise damage
    return written
