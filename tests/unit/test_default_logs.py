"""A run given no log records to ``runs/<script>-<time>.jsonl``, opened exclusively: processes started
in the same second (the one-laptop fleet set-up starts its robots so) each get a file of their own,
never one file between them (fsmscope/server/runner.py ``open_recorder``)."""

from __future__ import annotations

import multiprocessing
import os
from pathlib import Path

from fsmscope.server.runner import open_recorder


def open_at_once(directory: str, barrier, paths) -> None:
    os.chdir(directory)
    barrier.wait()
    path, recorder = open_recorder(None, False, "run", "twin.py")
    paths.put(path if recorder is not None else None)
    barrier.wait()  # every log open at once before any closes (a log that received nothing is removed)
    if recorder is not None:
        recorder.close()


def test_runs_started_in_the_same_second_record_to_logs_of_their_own(tmp_path: Path) -> None:
    context = multiprocessing.get_context("fork")
    barrier, paths = context.Barrier(8), context.Queue()
    workers = [context.Process(target=open_at_once, args=(str(tmp_path), barrier, paths)) for _ in range(8)]
    for worker in workers:
        worker.start()
    for worker in workers:
        worker.join(30)
    opened = [paths.get(timeout=5) for _ in workers]
    assert None not in opened and len(set(opened)) == 8

