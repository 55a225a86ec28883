"""`fsmscope export LOG --mcap OUT.mcap` and `fsmscope replay OUT.mcap`: the file read back by the mcap
library (channels, schemas, counts), the transcript of the MCAP the JSONL's, a file cut short still
read up to the cut."""

from __future__ import annotations

import fsm
import pytest
from export_support import NAME, exported_run
from mcap.reader import make_reader
from recording_support import cli, record, two_state_loop

from fsm.logfiles.log_reader import read_events
from fsm.observation import schema
from fsmscope.interop.mcap_log import McapLogError, read_mcap, write_mcap

STATE_KINDS = ("structure", "start", "transition", "terminate")


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return exported_run(tmp_path_factory)


@pytest.fixture(scope="module")
def mcap(run):
    out = run.log.with_suffix(".mcap")
    done = cli("export", run.log, "--mcap", out)
    assert done.returncode == 0, done.stderr
    return out


def summary(path):
    with open(path, "rb") as f:
        s = make_reader(f).get_summary()
    counts = s.statistics.channel_message_counts
    return {c.topic: (c.message_encoding, s.schemas[c.schema_id].name, s.schemas[c.schema_id].encoding, counts[i])
            for i, c in s.channels.items()}


def test_the_file_has_the_events_the_active_states_and_the_log_lines_on_their_channels(run, mcap):
    events = [e for e in read_events(str(run.log)) if e["kind"] != "snapshot"]
    channels = summary(mcap)
    assert channels["/fsmscope/%s/events" % NAME] == ("json", "fsmscope.Event", "jsonschema", len(events))
    assert channels["/fsmscope/%s/state" % NAME] == ("json", "fsmscope.State", "jsonschema",
                                                     sum(e["kind"] in STATE_KINDS for e in events))
    encoding, name, schema_encoding, lines = channels["/fsmscope/log"]
    assert (encoding, name, schema_encoding) == ("protobuf", "foxglove.Log", "protobuf") and lines > len(events) / 2


def test_replaying_the_mcap_prints_what_replaying_the_log_prints(run, mcap):
    from_log, from_mcap = cli("replay", run.log, "--no-time"), cli("replay", mcap, "--no-time")
    assert from_mcap.returncode == from_log.returncode == 0, from_mcap.stderr
    assert from_mcap.stdout == from_log.stdout


def test_the_events_read_back_are_the_events_written(run, mcap):
    assert list(read_mcap(str(mcap))) == [e for e in read_events(str(run.log)) if e["kind"] != "snapshot"]


def test_a_pose_becomes_frame_transforms_of_its_bodies(tmp_path):
    events = [schema.event(1, 1.0, "r", "arm", "pose", "/SM_ROOT",
                           {"joints": {"j1": 0.5}, "bodies": {"cube": [0.1, 0.2, 0.3, 1.0, 0.0, 0.0, 0.0],
                                                              "cup": [0.0, 0.0, 0.1, 1.0, 0.0, 0.0, 0.0]}}),
              schema.event(2, 2.0, "r", "arm", "pose", "/SM_ROOT",
                           {"joints": {"j1": 0.6}, "bodies": {"cube": [0.1, 0.2, 0.4, 1.0, 0.0, 0.0, 0.0]}})]
    write_mcap(events, str(tmp_path / "pose.mcap"))
    assert summary(tmp_path / "pose.mcap")["/tf"] == ("protobuf", "foxglove.FrameTransform", "protobuf", 3)


@pytest.fixture
def cut_short(tmp_path):
    """(the events of a 3,000-step loop, their MCAP file cut at two thirds of its size)."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    _, events = record(two_state_loop(3000), tmp_path / "loop.jsonl", name="loop")
    whole = tmp_path / "loop.mcap"
    write_mcap(events, str(whole))
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(whole.read_bytes()[: whole.stat().st_size * 2 // 3])
    return events, cut


def test_a_file_cut_short_yields_the_events_before_the_cut_then_says_so(cut_short):
    events, cut = cut_short
    read = []
    with pytest.raises(McapLogError, match="damaged after"):
        for event in read_mcap(str(cut)):
            read.append(event)
    assert 0 < len(read) < len(events) and read == events[:len(read)]


def test_replaying_a_file_cut_short_replays_what_came_before_and_exits_1(cut_short):
    done = cli("replay", cut_short[1], "--no-time")
    assert done.returncode == 1 and "damaged after" in done.stderr and "events before it were kept" in done.stderr
    assert "State machine transitioning 'A':'go'-->'B'" in done.stdout


def test_exporting_over_an_existing_file_is_refused(run, tmp_path):
    out = tmp_path / "there.mcap"
    out.write_bytes(b"keep")
    done = cli("export", run.log, "--mcap", out)
    assert done.returncode == 2 and "exists already" in done.stderr and out.read_bytes() == b"keep"


def test_the_demo_arm_is_exported_as_a_frame_per_body_at_every_recorded_pose(headless_demo_log, tmp_path):
    from fsmscope.sim.pose import PoseFrames

    out = tmp_path / "demo.mcap"
    done = cli("export", headless_demo_log, "--mcap", out)
    assert done.returncode == 0, done.stderr
    poses = sum(e["kind"] == "pose" for e in read_events(str(headless_demo_log)))
    bodies = PoseFrames().model.nbody - 1
    assert poses > 0
    assert summary(out)["/tf"] == ("protobuf", "foxglove.FrameTransform", "protobuf", poses * bodies)
