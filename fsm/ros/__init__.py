"""What smach_ros and ROS provided, without ROS: an in-process bus (topics, services), a minimal
actionlib, and the states built on them (ServiceState, SimpleActionState, MonitorState,
ConditionState). Built on ``fsm.core``; the core never imports it."""
