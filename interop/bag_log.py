"""A bag's SMACH runs written as fsmscope's own log (the recorder's JSON Lines, with its snapshots
and index), so that replay, the dashboard, time travel and export work on them unchanged."""

from __future__ import annotations

import os

from fsm.logfiles.recorder import Recorder, index_path

from .bag_reader import BagError, read_bag
from .smach_events import events


class BagDamaged(BagError):
    """The bag is damaged part way: ``written`` events came before the damage, and were kept."""

    def __init__(self, message: str, written: int) -> None:
        super().__init__(message)
        self.written = written


def write_log(bag: str, log: str) -> int:
    """Every event of the bag's SMACH runs into a new file ``log``; the number written. Raises
    ``BagError`` when nothing can be read (no file is left), ``BagDamaged`` when part can."""
    if os.path.exists(log):
        raise BagError("%s exists already: fsmscope import writes a new log" % log)
    written = 0
    partial = log + ".partial"
    try:
        with Recorder(partial) as recorder:
            try:
                for event in events(read_bag(bag)):
                    recorder(event)
                    written += 1
            except BagError as exc:
                if not written:
                    raise
                damage = BagDamaged(str(exc), written)
            else:
                damage = None
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
