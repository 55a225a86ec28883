"""A recording of a machine of the original SMACH (each branch's core) replays: its transcript
(fsm.logfiles.transcript, what ``fsmscope replay`` prints) is the lines SMACH printed live, word for
word, and the state rebuilt from the log is the one the live events built."""

import pytest
from fsm.logfiles.log_reader import read_events
from fsm.logfiles.transcript import messages
from fsm.observation.status import rebuild

from original_support import RACY, SCENARIOS, run
from parity_support import normalised

pytestmark = pytest.mark.timeout(30)

# A Concurrence's lines of its outcome choice: printed, not sent (as fsm's: fsm.core.log.debug_quiet).
PRINTED_ONLY = {("debug", "SMACH Concurrence determining contained state outcomes."),
                ("debug", "Terminating concurrent split with mapped outcome.")}


@pytest.mark.parametrize("scenario", sorted(SCENARIOS))
def test_the_recording_of_an_original_machine_replays_the_lines_it_printed_live(core, scenario, tmp_path):
    log = tmp_path / "run.jsonl"
    live = run(core, SCENARIOS[scenario], log)
    replayed = normalised([(line.level, line.msg) for line in messages(read_events(log))])
    printed = [line for line in live["logs"] if tuple(line) not in PRINTED_ONLY]
    if scenario in RACY:
        replayed, printed = sorted(replayed), sorted(printed)
    assert replayed == printed


@pytest.mark.parametrize("scenario", sorted(SCENARIOS))
def test_the_state_rebuilt_from_the_recording_is_the_live_one(core, scenario, tmp_path):
    log = tmp_path / "run.jsonl"
    live = run(core, SCENARIOS[scenario], log)["events"]
    recorded = [e for e in read_events(log) if e["kind"] != "snapshot"]
    assert recorded == live
    assert rebuild(recorded)["m"].to_dict() == rebuild(live)["m"].to_dict()
