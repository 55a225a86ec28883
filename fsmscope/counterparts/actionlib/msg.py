"""actionlib.msg, ROS-free: the Test and TwoInts actions actionlib ships (Debian's python3-actionlib),
each as its seven classes (TestAction, TestGoal, TestResult, TestFeedback, ...)."""

from fsmscope.counterparts.messages import action

globals().update(action("actionlib/Test", {"goal": 0}, {"result": 0}, {"feedback": 0}))
globals().update(action("actionlib/TwoInts", {"a": 0, "b": 0}, {"sum": 0}, {}))
