"""The robotics world's files: ROS bags of SMACH runs (rosbags) turned into fsmscope's events.

Like ``sim``, it knows nothing of the server: the CLI composes it with the log and the dashboard.
"""
