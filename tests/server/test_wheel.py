"""fsmscope as a robot's Python environment gets it: the wheel built from this checkout, installed
into a fresh virtual environment with pip, used from a folder that is not the checkout.

One module-scoped install (about a minute: the wheel's build, a venv, its dependencies from pip's
cache) serves every test here.
"""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from recording_support import EXAMPLES, ROOT

# What the fsmscope distribution may put at the top of site-packages (besides its dist-info and
# its command in bin/): the runtime users import as ``fsm``, and everything else under ``fsmscope``.
OWN_TOP_LEVEL = {"fsm", "fsmscope"}
FORMER_TOP_LEVEL = ("server", "sim", "static", "interop", "fleet")


class Installed:
    """A fresh venv holding the wheel; ``run`` runs its programs from ``cwd``, away from the checkout."""

    def __init__(self, venv: Path, cwd: Path) -> None:
        self.venv = venv
        self.cwd = cwd
        self.env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}

    def run(self, program: str, *args: str, timeout: float = 120) -> subprocess.CompletedProcess:
        return subprocess.run([str(self.venv / "bin" / program), *args], cwd=self.cwd, env=self.env,
                              capture_output=True, text=True, timeout=timeout)

    def python(self, code: str) -> str:
        done = self.run("python", "-c", code)
        assert done.returncode == 0, done.stderr
        return done.stdout.strip()


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> Installed:
    base = tmp_path_factory.mktemp("wheel")
    built = subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(base / "dist"),
                            str(ROOT)], capture_output=True, text=True, timeout=300)
    assert built.returncode == 0, built.stderr
    wheels = list((base / "dist").glob("fsmscope-*.whl"))
    assert len(wheels) == 1, wheels
    venv = base / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=120)
    away = base / "elsewhere"
    away.mkdir()
    env = Installed(venv, away)
    done = env.run("pip", "install", "-q", str(wheels[0]), timeout=600)
    assert done.returncode == 0, done.stderr
    return env


def test_the_wheel_installs_only_fsm_and_fsmscope_at_the_top_of_site_packages(installed):
    names = installed.python("import importlib.metadata as m\n"
                             "print(' '.join(sorted({f.parts[0] for f in m.files('fsmscope')})))").split()
    own = {name for name in names if name != ".." and not name.endswith(".dist-info")}
    assert own == OWN_TOP_LEVEL


def test_the_former_top_level_packages_are_not_importable_from_the_install(installed):
    found = installed.python("import importlib.util\n"
                             "print(' '.join(n for n in %r if importlib.util.find_spec(n)))" % (FORMER_TOP_LEVEL,))
    assert found == ""


def test_the_public_api_imports_from_the_top_of_the_package(installed):
    names = installed.python("from fsmscope import IntrospectionServer, Publisher, attach, Recorder\n"
                             "print(IntrospectionServer.__module__, Publisher.__module__, attach.__module__)")
    assert names == "fsmscope.server.introspection_server fsmscope.server.publisher fsm.observation.introspection"


def test_the_dashboards_files_are_installed_with_the_package(installed):
    files = installed.python("from fsmscope.server.static_files import static_dir\nimport os\n"
                             "d = static_dir()\nprint(d.startswith(%r), sorted(os.listdir(d)))" % str(installed.venv))
    assert files.startswith("True") and "'index.html'" in files and "'app.js'" in files and "'offline'" in files


def test_the_fsmscope_command_answers_help(installed):
    done = installed.run("fsmscope", "--help")
    assert done.returncode == 0, done.stderr
    assert "run" in done.stdout and "replay" in done.stdout


def test_python_dash_m_fsmscope_is_the_same_command(installed):
    done = installed.run("python", "-m", "fsmscope", "--help")
    assert done.returncode == 0, done.stderr
    assert done.stdout == installed.run("fsmscope", "--help").stdout


def test_the_installed_command_runs_and_records_an_example(installed):
    log = installed.cwd / "foo_bar.jsonl"
    done = installed.run("fsmscope", "run", "--no-serve", os.path.join(EXAMPLES, "foo_bar.py"), "--record", str(log))
    assert done.returncode == 0, done.stderr
    replayed = installed.run("fsmscope", "replay", str(log))
    assert replayed.returncode == 0, replayed.stderr
    assert "/SM_ROOT: FOO --outcome2--> end  x1" in replayed.stdout


def test_the_installed_command_runs_an_unchanged_ros_tutorial_on_its_counterparts(installed):
    log = installed.cwd / "tutorial.jsonl"
    done = installed.run("fsmscope", "run", "--no-serve", os.path.join(EXAMPLES, "tutorial_service_action.py"),
                         "--record", str(log))
    assert done.returncode == 0, done.stderr
    assert "smach is not installed: running the script on fsm" in done.stderr
    assert "The state machine ended in succeeded with sum=5" in done.stdout
