"""Where cyclonedds has no wheel (a robot's aarch64 Linux), fsmscope installs without it
(pyproject.toml's marker) and ``fsmscope ros2`` says what is missing rather than failing on an import."""

import sys

from fsmscope.server.cli import main


def test_fsmscope_ros2_without_cyclonedds_says_what_to_install(monkeypatch, capsys):
    # `import cyclonedds` and its modules raise ImportError, also where an earlier test imported them.
    for name in ["cyclonedds", *[n for n in sys.modules if n.startswith("cyclonedds.")]]:
        monkeypatch.setitem(sys.modules, name, None)
    for name in [n for n in sys.modules if n == "fsmscope.ros2" or n.startswith("fsmscope.ros2.")]:
        monkeypatch.delitem(sys.modules, name)
    assert main(["ros2", "--port", "0"]) == 1
    said = capsys.readouterr().err
    assert "ROS 2 needs the cyclonedds package" in said and "pip install cyclonedds" in said
