"""Events read from another format (a ROS bag's SMACH runs, an MCAP file) written as fsmscope's own
log (the recorder's JSON Lines, with its snapshots and index), so that replay, the dashboard, time
travel and export work on them unchanged."""

from __future__ import annotations

import os
from typing import Iterable

from fsm.logfiles.recorder import Recorder, index_path


class ReadError(Exception):
    """The source cannot be read; the message says why."""


class NotWritten(Exception):
    """The log cannot be written (a full disk); no file is left. The message says why."""


class Damaged(ReadError):
    """The source is damaged part way: ``written`` events came before the damage, and were kept."""

    def __init__(self, message: str, written: int) -> None:
        super().__init__(message)
        self.written = written


def write_log(events: Iterable[dict], log: str) -> int:
    """``events`` into a new file ``log``; the number written. Raises ``ReadError`` (from the source)
    when nothing can be read (no file is left), ``Damaged`` when part can, ``NotWritten`` when the
    log cannot be written whole (no file is left)."""
    if os.path.exists(log):
        raise ReadError("%s exists already: a new log is written" % log)
    written = 0
    damage = None
    partial = log + ".partial"
    try:
        with Recorder(partial) as recorder:
            try:
                for event in events:
                    recorder(event)
                    written += 1
            except ReadError as exc:
                if not written:
                    raise
                damage = Damaged(str(exc), written)
        if recorder.failure is not None:
            raise NotWritten("%s not written: %s" % (log, recorder.failure.strerror or recorder.failure))
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
