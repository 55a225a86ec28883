"""ROS-free counterpart of actionlib_msgs (see fsmscope/counterparts/__init__.py): ``actionlib_msgs.msg``."""
