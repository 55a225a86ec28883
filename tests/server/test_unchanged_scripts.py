"""``fsmscope run`` on unchanged SMACH scripts, in real processes: the two ROS 1 tutorials run on fsm
with ROS-free rospy and smach_ros where smach is not installed (saying so in one line), the original
smach's machines are recorded where it is installed, and an import that cannot be served says why."""

import contextlib
import json
import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import httpx
import pytest
from fsm.logfiles.log_reader import read_events

from recording_support import EXAMPLES, ROOT, cli
from fsmscope.server.testing.polling import wait_for

NOTICE = "fsmscope: smach is not installed: running the script on fsm, fsmscope's SMACH-compatible runtime"
REFERENCE = Path(ROOT).parent / "shared/reference/executive_smach"
ORIGINAL_SRC = REFERENCE / "noetic/smach/src"
CORES = {"noetic": ORIGINAL_SRC, "ros2": REFERENCE / "ros2/smach"}  # where each branch's smach package is


def run_script(script, log, pythonpath=None):
    """``fsmscope run --exit --no-serve --record LOG SCRIPT``, with ``pythonpath`` before the project's."""
    env = {"PYTHONPATH": str(pythonpath)} if pythonpath is not None else {}
    return cli("run", "--exit", "--no-serve", "--record", log, script, env=env)


def write_script(tmp_path, text, name="task.py"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_the_foo_bar_tutorial_runs_on_fsm_without_ros_and_records_its_machine(tmp_path):
    log = tmp_path / "run.jsonl"
    done = run_script(os.path.join(EXAMPLES, "tutorial_foo_bar.py"), log)
    assert done.returncode == 0, done.stderr
    assert done.stderr.count(NOTICE) == 1
    events = list(read_events(log))
    assert {e["machine"] for e in events} == {"tutorial_foo_bar"}
    assert [e["to"] for e in events if e["kind"] == "transition"] == ["BAR", "FOO"] * 3
    assert [e["outcome"] for e in events if e["kind"] == "terminate"] == ["outcome4"]
    assert [e["msg"] for e in events if e["kind"] == "log"][:2] == ["Executing state FOO", "Executing state BAR"]


def test_the_service_action_tutorial_calls_its_service_and_action_on_fsm(tmp_path):
    log = tmp_path / "run.jsonl"
    done = run_script(os.path.join(EXAMPLES, "tutorial_service_action.py"), log)
    assert done.returncode == 0, done.stderr
    assert done.stderr.count(NOTICE) == 1
    assert "The state machine ended in succeeded with sum=5" in done.stdout
    events = list(read_events(log))
    assert [(e["from"], e["outcome"], e["to"]) for e in events if e["kind"] == "transition"] == \
        [("STATE1", "succeeded", "STATE2")]
    assert "enable service called with data=True" in [e["msg"] for e in events if e["kind"] == "log"]
    assert [e["changes"] for e in events if "changes" in e] == [{"sum": 5}]
    assert [e["outcome"] for e in events if e["kind"] == "terminate"] == ["succeeded"]


def test_a_script_on_fsm_itself_gets_no_notice(tmp_path):
    done = run_script(os.path.join(EXAMPLES, "foo_bar.py"), tmp_path / "run.jsonl")
    assert done.returncode == 0, done.stderr
    assert "smach is not installed" not in done.stderr


@contextlib.contextmanager
def served_run(script, log, pythonpath=None):
    """``fsmscope run --record LOG SCRIPT`` serving its dashboard: yields an HTTP client of the
    dashboard once the script has ended; Ctrl-C then ends it, which must exit 0."""
    paths = ([str(pythonpath)] if pythonpath is not None else []) + [ROOT]
    proc = subprocess.Popen([sys.executable, "-m", "fsmscope", "run", "--record", str(log), str(script)], cwd=ROOT,
                            env=dict(os.environ, PYTHONPATH=os.pathsep.join(paths)), stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE, text=True)
    try:
        said = []
        for line in proc.stderr:
            said.append(line)
            if "the script ended" in line:
                break
        address = re.search(r"dashboard at (http://[^/]+)/\?token=(\S+)", "".join(said))
        assert address, said
        base, token = address.groups()
        with httpx.Client(base_url=base, headers={"Authorization": "Bearer " + token}, timeout=10) as http:
            yield http
        proc.send_signal(signal.SIGINT)
        assert proc.wait(20) == 0
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def runs_again_from_the_dashboard(http, machine, outcome):
    """The served ``machine`` ended in ``outcome``; started again from the dashboard, it ends so again."""
    status = http.get("/api/machines/%s/status" % machine).json()
    assert (status["running"], status["outcome"]) == (False, outcome)
    assert http.post("/api/machines/%s/start" % machine, json={}).status_code == 202

    def the_new_run_ended():
        now = http.get("/api/machines/%s/status" % machine).json()
        return now["run"] != status["run"] and not now["running"] and now["outcome"] == outcome
    wait_for(the_new_run_ended, 10, interval=0.02, what="the run started from the dashboard to end")


def test_a_tutorials_machine_is_served_and_runs_again_from_the_dashboard_after_the_script_ended(tmp_path):
    log = tmp_path / "run.jsonl"
    with served_run(os.path.join(EXAMPLES, "tutorial_foo_bar.py"), log) as http:
        runs_again_from_the_dashboard(http, "tutorial_foo_bar", "outcome4")
    assert json.loads(cli("replay", log, "--json").stdout)["machines"]["tutorial_foo_bar"]["runs"] == 2


def test_a_ros_import_without_a_counterpart_fails_naming_the_module(tmp_path):
    script = write_script(tmp_path, "import rospy\nimport smach\nfrom geometry_msgs.msg import Pose\n")
    done = run_script(script, tmp_path / "run.jsonl")
    assert done.returncode == 1
    assert ("ModuleNotFoundError: No module named 'geometry_msgs': smach is not installed, so fsmscope runs "
            "this script on fsm without ROS, and has no ROS-free counterpart of 'geometry_msgs'") in done.stderr


def test_a_part_of_rospy_without_a_counterpart_says_so(tmp_path):
    script = write_script(tmp_path, "import rospy\nrospy.get_param('~rate', 10)\n")
    done = run_script(script, tmp_path / "run.jsonl")
    assert done.returncode == 1
    assert ("AttributeError: rospy.get_param: fsmscope runs this script without ROS, and its ROS-free rospy "
            "has no get_param") in done.stderr


def test_smach_is_not_importable_outside_fsmscope_run():
    done = subprocess.run([sys.executable, "-c", "import fsmscope.server.runner, smach"], cwd=ROOT,
                          env=dict(os.environ, PYTHONPATH=ROOT), capture_output=True, text=True, timeout=60)
    assert done.returncode == 1
    assert done.stderr.strip().endswith("ModuleNotFoundError: No module named 'smach'")


@pytest.mark.parametrize("init, reason", [
    ("import smach_yaml_dependency\n", "ModuleNotFoundError: No module named 'smach_yaml_dependency'"),
    ("def broken(:\n    pass\n", "SyntaxError: invalid syntax (__init__.py, line 1)"),
], ids=["missing-dependency", "syntax-error"])
def test_a_broken_smach_says_its_own_reason_and_not_the_fallback(tmp_path, init, reason):
    site = tmp_path / "site"
    (site / "smach").mkdir(parents=True)
    (site / "smach" / "__init__.py").write_text(init)
    script = write_script(tmp_path, "import smach\n")
    done = run_script(script, tmp_path / "run.jsonl", pythonpath=site)
    assert done.returncode == 1
    assert ("fsmscope run: smach is installed (%s) but cannot be imported: %s"
            % (site / "smach" / "__init__.py", reason)) in done.stderr
    assert NOTICE not in done.stderr


needs_original = pytest.mark.skipif(not ORIGINAL_SRC.is_dir(), reason="the original SMACH core is not at %s "
                                    "(a copy of shared/ beside the project root)" % ORIGINAL_SRC)

FOO_BAR_ON_SMACH = """\
import smach


class Foo(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=['outcome1', 'outcome2'])
        self.counter = 0

    def execute(self, userdata):
        smach.loginfo('Executing state FOO')
        if self.counter < 3:
            self.counter += 1
            return 'outcome1'
        return 'outcome2'


class Bar(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=['outcome2'])

    def execute(self, userdata):
        return 'outcome2'


sm = smach.StateMachine(outcomes=['outcome4'])
with sm:
    smach.StateMachine.add('FOO', Foo(), transitions={'outcome1': 'BAR', 'outcome2': 'outcome4'})
    smach.StateMachine.add('BAR', Bar(), transitions={'outcome2': 'FOO'})
print('ran on', smach.__file__, 'to', sm.execute())
"""


@needs_original
@pytest.mark.parametrize("branch", sorted(CORES))
def test_a_machine_of_the_original_smach_is_recorded(tmp_path, branch):
    log = tmp_path / "run.jsonl"
    done = run_script(write_script(tmp_path, FOO_BAR_ON_SMACH), log, pythonpath=CORES[branch])
    assert done.returncode == 0, done.stderr
    assert "ran on %s to outcome4" % (CORES[branch] / "smach" / "__init__.py") in done.stdout
    assert NOTICE not in done.stderr
    events = list(read_events(log))
    assert {e["machine"] for e in events} == {"task"}
    assert [e["to"] for e in events if e["kind"] == "transition"] == ["BAR", "FOO"] * 3
    assert [e["outcome"] for e in events if e["kind"] == "terminate"] == ["outcome4"]


NESTED_ON_SMACH = """\
import smach


def leaf(outcome):
    return smach.CBState(lambda ud: outcome, outcomes=[outcome])


def build():
    inner = smach.StateMachine(outcomes=['done'])
    with inner:
        smach.StateMachine.add('LEAF', leaf('done'), transitions={'done': 'done'})
    both = smach.Concurrence(outcomes=['done'], default_outcome='done', outcome_map={'done': {'INNER': 'done'}})
    with both:
        smach.Concurrence.add('INNER', inner)
        smach.Concurrence.add('OTHER', leaf('done'))
    top = smach.StateMachine(outcomes=['end'])
    with top:
        smach.StateMachine.add('BOTH', both, transitions={'done': 'AGAIN'})
        smach.StateMachine.add('AGAIN', leaf('again'), transitions={'again': 'end'})
    return top


build().execute()
build().execute()
"""


@needs_original
def test_a_machine_of_the_original_smach_is_served_and_runs_again_from_the_dashboard(tmp_path):
    log = tmp_path / "run.jsonl"
    with served_run(write_script(tmp_path, FOO_BAR_ON_SMACH), log, ORIGINAL_SRC) as http:
        assert [m["name"] for m in http.get("/api/machines").json()] == ["task"]
        runs_again_from_the_dashboard(http, "task", "outcome4")
    assert json.loads(cli("replay", log, "--json").stdout)["machines"]["task"]["runs"] == 2


@needs_original
@pytest.mark.parametrize("branch", sorted(CORES))
def test_each_top_level_machine_of_the_original_smach_is_recorded_with_its_nested_ones_inside(tmp_path, branch):
    log = tmp_path / "run.jsonl"
    done = run_script(write_script(tmp_path, NESTED_ON_SMACH), log, pythonpath=CORES[branch])
    assert done.returncode == 0, done.stderr
    ends = [(e["machine"], e["path"], e["outcome"]) for e in read_events(log) if e["kind"] == "terminate"]
    assert ends == [(machine, path, outcome) for machine in ("task", "task-2") for path, outcome in
                    (("/SM_ROOT/BOTH/INNER", "done"), ("/SM_ROOT/BOTH", "done"), ("/SM_ROOT", "end"))]


@needs_original
def test_beside_the_original_smach_a_missing_rospy_is_said_to_be_needed(tmp_path):
    done = run_script(os.path.join(EXAMPLES, "tutorial_foo_bar.py"), tmp_path / "run.jsonl", pythonpath=ORIGINAL_SRC)
    assert done.returncode == 1
    assert ("No module named 'rospy': smach is installed (%s), so fsmscope runs this script on it as it is"
            % (ORIGINAL_SRC / "smach" / "__init__.py")) in done.stderr
