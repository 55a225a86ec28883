"""A --stop-topic that is not a ROS name is a clear error of the command, before anything is joined or served."""

import pytest

from fsmscope.server.cli import main


@pytest.mark.parametrize("command", [["ros1", "--master", "http://127.0.0.1:9/"], ["serve", "--ros1", "http://127.0.0.1:9/"]])
def test_a_stop_topic_that_is_no_ros_name_is_said(command, capsys):
    assert main([*command, "--port", "0", "--stop-topic", "r1=sm stop"]) == 1
    assert "--stop-topic r1=sm stop: a topic is a ROS name that starts with /" in capsys.readouterr().err
