"""The fsmscope command line, in real processes: run, replay and their exit codes."""

import contextlib
import json
import os
import queue
import re
import signal
import socket
import subprocess
import sys
import threading

import httpx
import pytest
from fsm.observation.encoding import dumps

from recording_support import EXAMPLES, ROOT, cli, replay_served
from fsmscope.server.testing.polling import wait_for


@pytest.fixture(scope="module")
def foo_bar_log(tmp_path_factory):
    path = tmp_path_factory.mktemp("cli") / "foo_bar.jsonl"
    done = cli("run", os.path.join(EXAMPLES, "foo_bar.py"), "--record", path)
    assert done.returncode == 0, done.stderr
    return path


@contextlib.contextmanager
def killed_if_left(proc: subprocess.Popen):
    """``proc`` for the test's block, killed if the block leaves it running (a failed check)."""
    try:
        yield proc
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_run_records_to_the_given_path_and_says_where(foo_bar_log):
    assert foo_bar_log.exists() and os.path.exists(str(foo_bar_log) + ".idx")


@pytest.mark.parametrize("command", [
    ["run", "SCRIPT", "--no-serve", "--record", "OUT"],
    ["demo", "--headless", "--record", "OUT"],
    ["export", "LOG", "--html", "OUT"],
    ["export", "LOG", "--mcap", "OUT"],
], ids=lambda v: " ".join(v[:2]))
def test_a_command_refuses_to_write_onto_an_existing_file_saying_so(command, foo_bar_log, tmp_path):
    out = tmp_path / "existing"
    out.write_bytes(b"keep")
    marker = tmp_path / "ran"
    script = tmp_path / "script.py"
    script.write_text("open(%r, 'w').close()\n" % str(marker))
    done = cli(*[{"SCRIPT": script, "LOG": foo_bar_log, "OUT": out}.get(a, a) for a in command])
    assert done.returncode == 2 and "%s exists already" % out in done.stderr, done.stderr
    assert out.read_bytes() == b"keep" and not marker.exists()


def test_a_run_that_cannot_start_leaves_no_log_to_refuse_the_next_time(tmp_path):
    log = tmp_path / "never.jsonl"
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        done = cli("run", os.path.join(EXAMPLES, "foo_bar.py"), "--record", log, "--port", taken.getsockname()[1])
    assert done.returncode == 1, done.stderr
    assert not log.exists() and not os.path.exists(str(log) + ".idx")


def test_run_appends_to_an_existing_log_when_asked(foo_bar_log, tmp_path):
    log = tmp_path / "twice.jsonl"
    for _ in range(2):
        assert cli("run", os.path.join(EXAMPLES, "foo_bar.py"), "--no-serve", "--record", log,
                   "--append").returncode == 0
    runs = {json.loads(line)["run"] for line in log.read_text().splitlines()}
    assert len(runs) == 2


def test_run_records_under_runs_by_default_and_prints_the_path(tmp_path):
    done = cli("run", os.path.join(EXAMPLES, "foo_bar.py"), cwd=tmp_path)
    assert done.returncode == 0
    logs = list((tmp_path / "runs").glob("foo_bar-*.jsonl"))
    assert len(logs) == 1
    assert os.path.join("runs", logs[0].name) in done.stderr


def test_run_passes_unknown_arguments_to_the_script(tmp_path):
    done = cli("run", os.path.join(EXAMPLES, "retry_abc.py"), "--seed", "7", "--record", tmp_path / "a.jsonl")
    again = cli("run", os.path.join(EXAMPLES, "retry_abc.py"), "--seed", "7", "--record", tmp_path / "b.jsonl")
    counts = [line for line in done.stdout.splitlines() if line.startswith("A_count=")]
    assert counts and counts == [line for line in again.stdout.splitlines() if line.startswith("A_count=")]


def test_run_passes_the_arguments_after_a_double_dash_to_the_script_without_it(tmp_path):
    script = tmp_path / "argv.py"
    script.write_text("import json, sys\nprint(json.dumps(sys.argv[1:]))\n")
    done = cli("run", script, "--record", tmp_path / "r.jsonl", "--", "--runs", "3")
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout.splitlines()[-1]) == ["--runs", "3"]


def test_run_names_a_second_machine_after_the_script_with_a_number(tmp_path):
    script = tmp_path / "twice.py"
    script.write_text("import runpy, sys\nsys.path.insert(0, %r)\nfrom foo_bar import build\n"
                      "build().execute()\nbuild().execute()\n" % EXAMPLES)
    log = tmp_path / "twice.jsonl"
    assert cli("run", script, "--record", log).returncode == 0
    summary = json.loads(cli("replay", log, "--json").stdout)
    assert list(summary["machines"]) == ["twice", "twice-2"]


def test_run_prints_smachs_info_lines_and_not_its_debug_lines_by_default(tmp_path):
    done = cli("run", os.path.join(EXAMPLES, "foo_bar.py"), "--record", tmp_path / "r.jsonl")
    assert done.returncode == 0, done.stderr
    assert "[  INFO ] : Executing state FOO" in done.stdout
    assert "[ DEBUG ]" not in done.stdout


def test_run_with_log_level_debug_prints_smachs_debug_lines_word_for_word(tmp_path):
    done = cli("run", os.path.join(EXAMPLES, "foo_bar.py"), "--log-level", "debug", "--record", tmp_path / "r.jsonl")
    assert done.returncode == 0, done.stderr
    assert "[ DEBUG ] : Adding state 'FOO' to the state machine." in done.stdout.splitlines()


def test_run_with_log_level_warn_prints_no_info_line(tmp_path):
    done = cli("run", os.path.join(EXAMPLES, "foo_bar.py"), "--log-level", "warn", "--record", tmp_path / "r.jsonl")
    assert done.returncode == 0, done.stderr
    assert "[  INFO ]" not in done.stdout


def test_run_says_the_dashboards_address_before_the_script_prints_anything(tmp_path):
    script = tmp_path / "chatty.py"
    script.write_text("print('the script speaks')\n")
    out = subprocess.run([sys.executable, "-m", "fsmscope", "run", "--exit", str(script), "--record",
                          str(tmp_path / "r.jsonl")], cwd=ROOT, capture_output=False, stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, text=True, timeout=60,
                         env=dict(os.environ, PYTHONPATH=ROOT, PYTHONUNBUFFERED="1"))
    lines = out.stdout.splitlines()
    assert lines[0].startswith("fsmscope: dashboard at http://127.0.0.1:"), lines
    assert lines.index("the script speaks") > 0


def test_run_accepts_no_serve_and_exit(tmp_path):
    done = cli("run", "--no-serve", "--exit", os.path.join(EXAMPLES, "foo_bar.py"), "--record", tmp_path / "r.jsonl")
    assert done.returncode == 0


def test_run_returns_the_script_exit_code(tmp_path):
    script = tmp_path / "fails.py"
    script.write_text("raise SystemExit(3)\n")
    assert cli("run", script, "--record", tmp_path / "r.jsonl").returncode == 3


def test_run_of_a_machine_holding_an_int_too_long_for_text_ends_as_it_does_without_fsmscope(tmp_path):
    script = tmp_path / "big.py"
    script.write_text("import fsm as smach\n"
                      "def put(ud):\n"
                      "    ud.big = 10 ** 5000\n"
                      "    return 'done'\n"
                      "sm = smach.StateMachine(['done'])\n"
                      "with sm:\n"
                      "    smach.StateMachine.add('PUT', smach.CBState(put, outcomes=['done'], output_keys=['big']), {})\n"
                      "print('outcome', sm.execute())\n")
    log = tmp_path / "big.jsonl"
    done = cli("run", "--no-serve", script, "--record", log)
    assert done.returncode == 0 and "outcome done" in done.stdout and "Traceback" not in done.stderr, done.stderr
    assert json.loads(cli("replay", log, "--json").stdout)["machines"]["big"]["outcome"] == "done"


def test_replay_prints_the_transcript_then_the_summary_and_exits_0(foo_bar_log):
    done = cli("replay", foo_bar_log)
    assert done.returncode == 0
    assert "/SM_ROOT [  INFO ] : State machine terminating 'FOO':'outcome2':'end'" in done.stdout
    assert "machine foo_bar: finished with outcome 'end'" in done.stdout


def test_replay_json_gives_the_summary_as_json(foo_bar_log):
    done = cli("replay", foo_bar_log, "--json")
    data = json.loads(done.stdout)
    assert data["exit_code"] == 0 and data["machines"]["foo_bar"]["outcome"] == "end"


def test_replay_exits_1_when_the_machine_ended_in_an_error(tmp_path):
    script = tmp_path / "bad.py"
    script.write_text("import fsm as smach\n"
                      "sm = smach.StateMachine(['done'])\n"
                      "with sm:\n"
                      "    smach.StateMachine.add('BAD', smach.CBState(lambda ud: 1 / 0, outcomes=['done']), {})\n"
                      "sm.execute()\n")
    log = tmp_path / "bad.jsonl"
    assert cli("run", script, "--record", log).returncode == 1
    done = cli("replay", log)
    assert done.returncode == 1
    assert "InvalidUserCodeError" in done.stdout


# What a terminal would obey: the window's title (OSC ... BEL), clear the screen (CSI 2J), go back
# over the line (CR, BS), the 8-bit CSI (U+009B), DEL.
ESCAPES = "\\x1b]0;pwned\\x07\\x1b[2J\\r\\x08\\u009b31m\\x7f"
OBEYED = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f]")


def test_replay_shows_the_control_characters_of_a_log_as_signs_never_raw(tmp_path):
    script = tmp_path / "loud.py"
    script.write_text("import fsm as smach\n"
                      "def loud(ud):\n"
                      "    smach.logwarn('message %s')\n"
                      "    raise ValueError('error %s')\n"
                      "sm = smach.StateMachine(['done'])\n"
                      "with sm:\n"
                      "    smach.StateMachine.add('LOUD', smach.CBState(loud, outcomes=['done']), {})\n"
                      "sm.execute()\n" % (ESCAPES, ESCAPES))
    log = tmp_path / "loud.jsonl"
    assert cli("run", script, "--record", log).returncode == 1
    done = cli("replay", log)
    assert done.returncode == 1
    assert not OBEYED.search(done.stdout + done.stderr), repr(OBEYED.findall(done.stdout + done.stderr))
    assert "message \u241b]0;pwned\u2407\u241b[2J\u240d\u2408\ufffd31m\u2421" in done.stdout
    assert "error \u241b]0;pwned" in done.stdout


BUSY = """
import fsm
sm = fsm.StateMachine(["done"])
n = [0]
def tick(ud):
    n[0] += 1
    ud.text = "x" * 200
    return "stop" if n[0] >= 3000 else "go"
with sm:
    fsm.StateMachine.add("A", fsm.CBState(tick, outcomes=["go", "stop"], output_keys=["text"]), {"go": "B", "stop": "done"})
    fsm.StateMachine.add("B", fsm.CBState(tick, outcomes=["go", "stop"], output_keys=["text"]), {"go": "A", "stop": "done"})
sm.execute()
"""


@pytest.fixture
def full_disk(tmp_path):
    """A folder on a real file system of 64 KiB (a tmpfs: mounting one needs root), which a run fills."""
    folder = tmp_path / "small"
    folder.mkdir()
    if subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(folder)], capture_output=True).returncode:
        pytest.skip("mounting a small tmpfs needs root")
    yield folder
    subprocess.run(["umount", str(folder)], check=True)


def test_a_run_whose_disk_fills_says_it_once_and_exits_1_keeping_the_events_before(full_disk, tmp_path):
    script = tmp_path / "busy.py"
    script.write_text(BUSY)
    log = full_disk / "busy.jsonl"
    done = cli("run", script, "--no-serve", "--record", log)
    assert done.returncode == 1, done.stderr
    assert "Traceback" not in done.stderr and done.stderr.count("could not write") == 1, done.stderr
    assert "No space left on device" in done.stderr
    replayed = cli("replay", log, "--json")
    assert json.loads(replayed.stdout)["events"] > 100


def test_an_import_whose_disk_fills_leaves_no_file_and_exits_2_saying_why(full_disk, tmp_path):
    script = tmp_path / "busy.py"
    script.write_text(BUSY)
    log, mcap = tmp_path / "busy.jsonl", tmp_path / "busy.mcap"
    assert cli("run", script, "--no-serve", "--record", log).returncode == 0
    assert cli("export", log, "--mcap", mcap).returncode == 0
    done = cli("import", mcap, "-o", full_disk / "busy.jsonl")
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    assert "%s not written: No space left on device" % (full_disk / "busy.jsonl") in done.stderr
    assert os.listdir(full_disk) == []


@pytest.mark.parametrize("option", ["--html", "--mcap"])
def test_an_export_whose_disk_fills_leaves_no_file_and_exits_2_saying_why(option, full_disk, tmp_path):
    script = tmp_path / "busy.py"
    script.write_text(BUSY)
    log = tmp_path / "busy.jsonl"
    assert cli("run", script, "--no-serve", "--record", log).returncode == 0
    out = full_disk / "busy.out"
    done = cli("export", log, option, out)
    assert done.returncode == 2 and "Traceback" not in done.stderr, done.stderr
    assert "%s not written: No space left on device" % out in done.stderr
    assert os.listdir(full_disk) == []


def test_replay_of_a_missing_file_is_a_one_line_error_with_exit_2(tmp_path):
    done = cli("replay", tmp_path / "missing.jsonl")
    assert done.returncode == 2
    assert done.stderr.strip().count("\n") == 0 and "no such file" in done.stderr


def test_replay_refuses_an_unknown_schema_version_with_exit_2(tmp_path):
    log = tmp_path / "future.jsonl"
    log.write_bytes(dumps({"v": 99, "seq": 1, "t": 0, "run": "r", "machine": "m", "kind": "start", "path": "/"}) + b"\n")
    done = cli("replay", log)
    assert done.returncode == 2 and "schema version 99 is not supported" in done.stderr


def test_replay_of_an_empty_file_is_unreadable_with_exit_2(tmp_path):
    log = tmp_path / "empty.jsonl"
    log.write_bytes(b"")
    done = cli("replay", log)
    assert done.returncode == 2
    assert "fsmscope replay: %s: no events (the file is empty)" % log in done.stderr


def test_replay_of_random_bytes_is_unreadable_with_exit_2(tmp_path):
    log = tmp_path / "noise.jsonl"
    log.write_bytes(bytes(range(256)) * 4)  # one newline in each 256 bytes: five lines of noise
    done = cli("replay", log, "--json")
    assert done.returncode == 2
    assert "fsmscope replay: %s: no events (5 lines skipped)" % log in done.stderr
    assert json.loads(done.stdout)["exit_code"] == 2


def test_replay_serve_of_an_empty_file_exits_2_instead_of_serving(tmp_path):
    log = tmp_path / "empty.jsonl"
    log.write_bytes(b"")
    done = cli("replay", log, "--serve", timeout=20)
    assert done.returncode == 2
    assert "fsmscope replay: %s: no events (the file is empty)" % log in done.stderr


@pytest.mark.parametrize("speed", ["0", "11", "nan", "fast"])
def test_replay_serve_refuses_a_speed_the_page_cannot_play(foo_bar_log, speed):
    done = cli("replay", foo_bar_log, "--serve", "--speed", speed, timeout=20)
    assert done.returncode == 2
    assert "--speed" in done.stderr and "Traceback" not in done.stderr


@pytest.mark.parametrize("command", [["serve"], ["run", os.path.join(EXAMPLES, "foo_bar.py")]],
                         ids=["serve", "run"])
def test_a_command_whose_port_is_taken_says_why_and_exits_1(tmp_path, command):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        done = cli(*command, "--port", taken.getsockname()[1], cwd=tmp_path, timeout=30)
    assert done.returncode == 1
    assert done.stderr.startswith("fsmscope %s: " % command[0]) and "already in use" in done.stderr
    assert "Traceback" not in done.stderr


def test_replay_reports_a_truncated_last_line_and_replays_the_rest(foo_bar_log, tmp_path):
    data = foo_bar_log.read_bytes()
    cut = tmp_path / "cut.jsonl"
    cut.write_bytes(data[:-10])
    n_lines = data.count(b"\n")
    done = cli("replay", cut)
    assert "line %d: truncated last line" % n_lines in done.stderr
    assert "State machine transitioning 'BAR':'outcome1'-->'FOO'" in done.stdout
    assert done.returncode == 1  # the terminate event was the line cut short


def test_replay_follow_tails_a_log_until_its_writer_closes_it(tmp_path):
    log = tmp_path / "live.jsonl"
    env = dict(os.environ, FSMSCOPE_TIME_SCALE="0.05", PYTHONPATH=ROOT)
    writer = subprocess.Popen([sys.executable, "-m", "fsmscope", "run", "--exit", os.path.join(EXAMPLES, "nested_monitor.py"),
                               "--record", str(log)], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        done = cli("replay", "--follow", log, timeout=30)
    finally:
        writer.wait(30)
    assert done.returncode == 0, done.stderr
    assert "machine nested_monitor: finished with outcome 'preempted'" in done.stdout


def test_run_records_the_runs_started_from_the_dashboard_after_the_script_ended(tmp_path):
    log = tmp_path / "rerun.jsonl"
    env = dict(os.environ, PYTHONPATH=ROOT)
    proc = subprocess.Popen([sys.executable, "-m", "fsmscope", "run", os.path.join(EXAMPLES, "foo_bar.py"),
                             "--record", str(log)], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                            text=True)
    lines = queue.Queue()
    threading.Thread(target=lambda: [lines.put(line) for line in proc.stderr], daemon=True).start()

    def line_matching(pattern):
        def next_line_matches():
            try:
                return re.search(pattern, lines.get(timeout=0.05))
            except queue.Empty:
                return None

        return wait_for(next_line_matches, 30, interval=0, what="a line matching %r" % pattern)

    with killed_if_left(proc):
        base, token = line_matching(r"dashboard at (http://[^/]+)/\?token=(\S+)").groups()
        line_matching("the script ended")
        http = httpx.Client(base_url=base, headers={"Authorization": "Bearer " + token}, timeout=10)
        first_run = http.get("/api/machines/foo_bar/status").json()["run"]
        assert http.post("/api/machines/foo_bar/start", json={}).status_code == 202

        def the_new_run_ended():
            status = http.get("/api/machines/foo_bar/status").json()
            return status["run"] != first_run and not status["running"] and status["outcome"] == "end"

        wait_for(the_new_run_ended, 10, interval=0.02, what="the run started from the dashboard to end")
        proc.send_signal(signal.SIGINT)
        assert proc.wait(20) == 0
    summary = json.loads(cli("replay", log, "--json").stdout)
    assert summary["machines"]["foo_bar"]["runs"] == 2 and summary["machines"]["foo_bar"]["outcome"] == "end"


SLEEPING_SCRIPT = """
import time
import fsm as smach

class Sleep(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=["done"])

    def execute(self, ud):
        print("sleeping", flush=True)
        time.sleep(60)
        return "done"

sm = smach.StateMachine(["done"])
with sm:
    smach.StateMachine.add("SLEEP", Sleep(), {"done": "done"})
sm.execute()
"""


@pytest.mark.parametrize("signum, code", [(signal.SIGTERM, 143), (signal.SIGINT, 130)], ids=["SIGTERM", "SIGINT"])
def test_one_signal_stops_run_and_its_dashboard_with_the_log_closed(tmp_path, signum, code):
    script = tmp_path / "sleepy.py"
    script.write_text(SLEEPING_SCRIPT)
    log = tmp_path / "sleepy.jsonl"
    proc = subprocess.Popen([sys.executable, "-m", "fsmscope", "run", str(script), "--record", str(log)],
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    with killed_if_left(proc):
        assert "sleeping\n" in proc.stdout  # reads the script's output up to the line (the machine is in SLEEP)
        proc.send_signal(signum)
        assert proc.wait(10) == code  # not still serving the dashboard
    last = json.loads(log.read_bytes().splitlines()[-1])
    assert (last["kind"], last["path"]) == ("terminate", "/SM_ROOT")
    assert json.loads(cli("replay", log, "--json").stdout)["problems"] == []


def test_ctrl_c_stops_a_command_started_with_sigint_ignored(foo_bar_log):
    # A non-interactive shell starts a command it puts in the background with SIGINT ignored.
    proc = subprocess.Popen([sys.executable, "-m", "fsmscope", "replay", str(foo_bar_log), "--serve"], cwd=ROOT,
                            stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_IGN))
    with killed_if_left(proc):
        assert any("replaying" in line for line in proc.stderr)  # up to the line with its address
        proc.send_signal(signal.SIGINT)
        assert proc.wait(20) == 0


def test_replay_serve_shows_a_recording_in_the_dashboard_as_view_only(foo_bar_log):
    with replay_served(foo_bar_log, "--speed", "2", "--token", "replay-token") as (url, _):
        base, headers = url.split("/?")[0], {"Authorization": "Bearer replay-token"}
        machines = {m["name"]: m for m in httpx.get(base + "/api/machines", headers=headers).json()}
        assert machines["foo_bar"]["source"] == "replay" and machines["foo_bar"]["outcome"] == "end"
        assert machines["foo_bar"]["replay"] == {"speed": 2.0}
        preempt = httpx.post(base + "/api/machines/foo_bar/preempt", json={}, headers=headers)
        assert preempt.status_code == 409 and "replayed" in preempt.json()["detail"]


@pytest.mark.parametrize("command, refused", [
    (["run", "SCRIPT", "--no-serve", "--viewer"], "--viewer has no meaning with --no-serve"),
    (["run", "SCRIPT", "--no-serve", "--port", "9999", "--deadman", "7.5"], "--port, --deadman has no meaning"),
    (["run", "SCRIPT", "--zenoh-connect", "tcp/127.0.0.1:7447"], "--zenoh-connect needs --zenoh ROBOT"),
    (["demo", "--headless", "--host", "0.0.0.0"], "--host has no meaning with --headless"),
    (["demo", "--headless", "--zenoh-token", "T"], "--zenoh-token needs --zenoh ROBOT"),
    (["serve", "--zenoh-scouting"], "--zenoh-scouting needs --zenoh"),
    (["serve", "--foxglove-origin", "null"], "--foxglove-origin needs --foxglove PORT"),
    (["run", "SCRIPT", "--append"], "--append needs --record"),
    (["run", "SCRIPT", "--no-serve", "--foxglove-host", "robot.local"], "--foxglove-host needs --foxglove PORT"),
    (["replay", "LOG", "--speed", "2"], "--speed needs --serve"),
    (["replay", "LOG", "--token", "t"], "--token needs --serve"),
    (["replay", "LOG", "--serve", "--follow"], "--follow has no meaning with --serve"),
    (["replay", "LOG", "--serve", "--json"], "--json has no meaning with --serve"),
    (["replay", "LOG", "--serve", "--foxglove", "0"], "--foxglove serves a live run's channels; a recorded one "
                                                       "opens in Foxglove as a file: fsmscope export"),
    (["export", "LOG", "--mcap", "OUT", "--max-mb", "1"], "--max-mb limits --html's page"),
], ids=lambda v: " ".join(v) if isinstance(v, list) else "")
def test_options_that_mean_nothing_together_are_refused_with_why(command, refused, foo_bar_log, tmp_path):
    args = [{"SCRIPT": os.path.join(EXAMPLES, "foo_bar.py"), "LOG": str(foo_bar_log), "OUT": str(tmp_path / "o.mcap")
             }.get(a, a) for a in command]
    done = subprocess.run([sys.executable, "-m", "fsmscope", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=30, env=dict(os.environ, PYTHONPATH=ROOT))
    assert done.returncode == 2 and refused in done.stderr, done.stderr
