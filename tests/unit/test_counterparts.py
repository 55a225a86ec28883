"""The ROS-free rospy, actionlib and smach_ros that ``fsmscope run`` gives a script where smach is not
installed: what a ROS script relies on behaves as ROS's does, in one process."""

import threading

import pytest

from fsmscope.counterparts.finder import ScriptImports


@pytest.fixture
def ros():
    """The counterparts, imported as a script run by ``fsmscope run`` imports them."""
    imports = ScriptImports(on_original=lambda module: None, say=lambda line: None)
    imports.install()
    try:
        import actionlib
        import rospy
        import smach
        import smach_ros
        from actionlib.msg import TwoIntsAction, TwoIntsGoal
        from std_msgs.msg import Bool
        from std_srvs.srv import SetBool
        rospy.init_node("test_node")
        yield dict(actionlib=actionlib, rospy=rospy, smach=smach, smach_ros=smach_ros, TwoIntsAction=TwoIntsAction,
                   TwoIntsGoal=TwoIntsGoal, Bool=Bool, SetBool=SetBool)
    finally:
        imports.uninstall()


def test_what_a_service_handler_returns_becomes_its_response_type_as_rospy_converts_it(ros):
    rospy, SetBool = ros["rospy"], ros["SetBool"]
    replies = iter([(True, "tuple"), {"success": True, "message": "dict"}])
    rospy.Service("~enable", SetBool, lambda request: next(replies))
    call = rospy.ServiceProxy("/test_node/enable", SetBool)
    assert [call(True), call(data=False)] == [SetBool._response_class(True, "tuple"),
                                            SetBool._response_class(True, "dict")]


def test_a_succeeded_goal_without_a_result_gives_the_actions_empty_result(ros):
    actionlib, TwoIntsAction = ros["actionlib"], ros["TwoIntsAction"]
    server = actionlib.SimpleActionServer("add", TwoIntsAction, execute_cb=lambda goal: server.set_succeeded())
    client = actionlib.SimpleActionClient("/add", TwoIntsAction)
    assert client.wait_for_server(ros["rospy"].Duration(5))
    client.send_goal(ros["TwoIntsGoal"](a=1, b=2))
    assert client.wait_for_result()
    assert (client.get_state(), client.get_result()) == (actionlib.GoalStatus.SUCCEEDED,
                                                         TwoIntsAction().action_result.result)


def test_a_simple_action_state_sends_the_actions_default_goal_with_its_slots_from_userdata(ros):
    smach, smach_ros, actionlib = ros["smach"], ros["smach_ros"], ros["actionlib"]
    goals = []
    server = actionlib.SimpleActionServer("add", ros["TwoIntsAction"],
                                          execute_cb=lambda goal: (goals.append(goal), server.set_succeeded()))
    sm = smach.StateMachine(outcomes=["succeeded", "aborted", "preempted"])
    sm.userdata.a = 4
    with sm:
        smach.StateMachine.add("ADD", smach_ros.SimpleActionState("add", ros["TwoIntsAction"], goal_slots=["a"]))
    assert sm.execute() == "succeeded"
    assert goals == [ros["TwoIntsGoal"](a=4, b=0)]


def test_a_message_published_on_a_relative_name_reaches_a_monitor_state_on_the_absolute_one(ros):
    smach, smach_ros, rospy, Bool = ros["smach"], ros["smach_ros"], ros["rospy"], ros["Bool"]
    sm = smach.StateMachine(outcomes=["valid", "invalid", "preempted"])
    with sm:
        smach.StateMachine.add("WATCH", smach_ros.MonitorState("/sm_stop", Bool, lambda ud, msg: not msg.data))
    publisher = rospy.Publisher("sm_stop", Bool, queue_size=1)
    result = []
    runner = threading.Thread(target=lambda: result.append(sm.execute()))
    runner.start()
    while runner.is_alive():
        publisher.publish(True)
        runner.join(0.01)
    assert result == ["invalid"]


def test_rospy_sleep_ends_with_ros_interrupt_exception_when_the_node_shuts_down(ros):
    rospy = ros["rospy"]
    threading.Timer(0.05, rospy.signal_shutdown, args=("test",)).start()
    with pytest.raises(rospy.ROSInterruptException):
        rospy.sleep(rospy.Duration(30))
    assert rospy.is_shutdown()


def test_a_machine_stops_when_the_node_shuts_down_as_with_smach_ros(ros):
    smach, rospy = ros["smach"], ros["rospy"]
    seen = []

    def once(ud):
        seen.append(1)
        rospy.signal_shutdown("done")
        return "again"
    sm = smach.StateMachine(outcomes=["end"])
    with sm:
        smach.StateMachine.add("A", smach.CBState(once, outcomes=["again"]), transitions={"again": "A"})
    sm.execute()
    assert seen == [1]


def test_rospy_log_lines_are_formatted_with_their_arguments_and_go_through_fsms_log(ros, logs):
    ros["rospy"].loginfo("Executing state %s (%d)", "FOO", 3)
    ros["rospy"].logwarn("100% sure")
    assert (logs.info, logs.warn) == (["Executing state FOO (3)"], ["100% sure"])


def test_a_condition_state_polls_at_a_rospy_duration_until_its_condition_holds(ros):
    smach, smach_ros, rospy = ros["smach"], ros["smach_ros"], ros["rospy"]
    checks = []
    sm = smach.StateMachine(outcomes=["true", "false", "preempted"])
    with sm:
        smach.StateMachine.add("WAIT", smach_ros.ConditionState(lambda ud: checks.append(1) or len(checks) == 3,
                                                                poll_rate=rospy.Duration(0.01), max_checks=-1))
    assert sm.execute() == "true"
    assert len(checks) == 3
