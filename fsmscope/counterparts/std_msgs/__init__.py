"""ROS-free counterpart of std_msgs (see fsmscope/counterparts/__init__.py): ``std_msgs.msg``."""
