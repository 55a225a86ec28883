"""ROS-free counterpart of std_srvs (see fsmscope/counterparts/__init__.py): ``std_srvs.srv``."""
