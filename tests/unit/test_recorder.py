"""fsm.logfiles.recorder: the JSON Lines log, its flushing, snapshots and index."""

import os
import signal
import subprocess
import struct
import sys
import textwrap
import threading
import time
from pathlib import Path

import fsm
import pytest
from fsm.observation.encoding import loads
from fsm.logfiles.log_reader import read_events, read_index, writer_active
from fsm.logfiles.recorder import LogBusy, Recorder
from fsm.observation.status import Status, rebuild

from recording_support import two_state_loop, ROOT, load_example, record



def _lines(path):
    with open(path, "rb") as handle:
        return [loads(line) for line in handle]


_loop = two_state_loop


def test_every_event_is_one_json_line_in_order(tmp_path):
    path = tmp_path / "run.jsonl"
    outcome, seen = record(load_example("foo_bar")["build"](), path)
    assert outcome == "end"
    assert _lines(path) == seen


def test_events_reach_the_file_within_100ms_without_close(tmp_path):
    path = tmp_path / "run.jsonl"
    recorder = Recorder(path)
    try:
        fsm.attach(_loop(3), recorder).root.execute()
        time.sleep(0.1)
        assert len(_lines(path)) == recorder.events > 0
    finally:
        recorder.close()


def test_close_is_idempotent_and_drops_later_events(tmp_path):
    path = tmp_path / "run.jsonl"
    sm = _loop(2)
    recorder = Recorder(path)
    fsm.attach(sm, recorder)
    sm.execute()
    recorder.close()
    recorder.close()
    size = os.path.getsize(path)
    sm.execute()
    assert os.path.getsize(path) == size


def test_snapshots_are_written_every_n_events_and_indexed_by_byte_offset(tmp_path):
    path = tmp_path / "run.jsonl"
    record(_loop(50), path, snapshot_every=10)
    index = read_index(path)
    assert len(index) >= 9
    with open(path, "rb") as handle:
        for entry in index:
            handle.seek(entry["offset"])
            line = loads(handle.readline())
            assert (line["kind"], line["machine"], line["seq"]) == ("snapshot", entry["machine"], entry["seq"])


def test_a_snapshot_plus_the_events_after_it_rebuild_the_same_status(tmp_path):
    path = tmp_path / "run.jsonl"
    record(_loop(50), path, snapshot_every=17)
    events = list(read_events(path))
    plain = [e for e in events if e["kind"] != "snapshot"]
    snapshot = [e for e in events if e["kind"] == "snapshot"][-1]
    status = Status.from_dict(snapshot["status"])
    for event in plain:
        if event["seq"] > snapshot["seq"]:
            status.apply(event)
    assert status.to_dict() == rebuild(plain)["m"].to_dict()


def test_a_recorder_given_the_events_by_hand_writes_the_snapshots_of_one_attached_to_the_machine(tmp_path):
    """The attached one reads the Status its machine's reporter folds; the other folds its own."""
    attached = tmp_path / "attached.jsonl"
    _, events = record(_loop(50), attached, snapshot_every=10)
    by_hand = tmp_path / "by_hand.jsonl"
    with Recorder(by_hand, snapshot_every=10) as recorder:
        for event in events:
            recorder(event)

    def snapshots(path):
        return [(e["seq"], e["status"]) for e in read_events(path) if e["kind"] == "snapshot"]
    assert len(snapshots(attached)) >= 9
    assert snapshots(by_hand) == snapshots(attached)


def test_machines_recorded_from_several_threads_keep_complete_sequences(tmp_path):
    path = tmp_path / "run.jsonl"
    with Recorder(path, snapshot_every=25) as recorder:
        machines = [_loop(200) for _ in range(4)]
        for i, sm in enumerate(machines):
            fsm.attach(sm, recorder, name="m%d" % i)
        threads = [threading.Thread(target=sm.execute) for sm in machines]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    events = [e for e in read_events(path) if e["kind"] != "snapshot"]
    for i in range(4):
        seqs = [e["seq"] for e in events if e["machine"] == "m%d" % i]
        assert seqs == list(range(1, len(seqs) + 1))
        assert rebuild(events)["m%d" % i].outcome == "done"


def test_appending_to_an_existing_log_keeps_index_offsets_right(tmp_path):
    path = tmp_path / "run.jsonl"
    record(_loop(30), path, name="first", snapshot_every=10)
    record(_loop(30), path, name="second", snapshot_every=10)
    entries = [e for e in read_index(path) if e["machine"] == "second"]
    assert entries
    with open(path, "rb") as handle:
        handle.seek(entries[0]["offset"])
        assert loads(handle.readline())["machine"] == "second"


def test_the_log_is_locked_while_a_recorder_writes_it(tmp_path):
    path = tmp_path / "run.jsonl"
    recorder = Recorder(path)
    assert writer_active(path)
    recorder.close()
    assert not writer_active(path)


KILLED_SCRIPT = textwrap.dedent("""
    import mmap, struct, sys, time
    sys.path.insert(0, {root!r})
    import fsm
    from fsm.logfiles.recorder import Recorder
    fsm.set_loggers(*[lambda m: None] * 4)

    class Tick(fsm.State):
        def __init__(self):
            fsm.State.__init__(self, ["go"])
        def execute(self, ud):
            time.sleep(0.001)
            return "go"

    sm = fsm.StateMachine(["never"])
    with sm:
        fsm.StateMachine.add("A", Tick(), {{"go": "B"}})
        fsm.StateMachine.add("B", Tick(), {{"go": "A"}})
    fsm.attach(sm, Recorder(sys.argv[1]))
    # The time of the newest event the machine made, in a page of memory the kernel keeps when the
    # process is killed: what the log must hold up to 100 ms of, whatever the load delayed.
    made_file = open(sys.argv[1] + ".made", "w+b")
    made_file.truncate(8)
    made = mmap.mmap(made_file.fileno(), 8)
    fsm.attach(sm, lambda event: made.__setitem__(slice(0, 8), struct.pack("d", event["t"])))
    print("running", flush=True)
    sm.execute()
""")


def test_a_recording_killed_with_sigkill_loses_at_most_the_last_100ms(tmp_path):
    path = tmp_path / "killed.jsonl"
    script = tmp_path / "forever.py"
    script.write_text(KILLED_SCRIPT.format(root=ROOT))
    proc = subprocess.Popen([sys.executable, str(script), str(path)], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "running"
        time.sleep(0.6)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(10)
    finally:
        if proc.poll() is None:
            proc.kill()
    last_made = struct.unpack("d", Path(str(path) + ".made").read_bytes())[0]
    events = [e for e in read_events(path) if e["kind"] != "snapshot"]
    assert [e["seq"] for e in events] == list(range(1, len(events) + 1))
    assert events[-1]["t"] >= last_made - 0.1, "lost %.3f s" % (last_made - events[-1]["t"])


def test_a_script_that_exits_without_closing_its_recorder_has_every_event_written(tmp_path):
    path = tmp_path / "run.jsonl"
    script = ("import sys, fsm\n"
              "sys.path.insert(0, %r)\n"
              "from recording_support import two_state_loop\n"
              "recorder = fsm.Recorder(%r, flush_interval=3600, flush_bytes=1 << 30)\n"
              "fsm.attach(two_state_loop(50), recorder).root.execute()\n"
              "sys.stderr.write(\"events=%%d\" %% recorder.events)\n") % (os.path.dirname(os.path.dirname(__file__)), str(path))
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    assert len(_lines(path)) == int(done.stderr.rsplit("events=", 1)[1]) > 100


def test_a_log_another_recorder_is_writing_is_not_opened_again(tmp_path):
    path = tmp_path / "run.jsonl"
    writing = Recorder(path, new=True)
    try:
        with pytest.raises(LogBusy, match="being written by another recorder"):
            Recorder(path)  # an --append of another process, as it meets the log
    finally:
        writing.close()
