"""ROS-free counterparts of ``smach``, ``smach_ros``, ``rospy`` and a few ROS packages, for the unchanged
SMACH scripts that ``fsmscope run`` runs where the original smach is not installed.

Each module here is loaded under the ROS name it stands in for (``smach``, ``rospy``...), and only by
``finder.ScriptImports``, which ``fsmscope run`` installs for its script's run: importing ``smach``
elsewhere still fails where it is not installed. What is covered, and what is not, is in
docs/guide.md ("Unchanged SMACH scripts"); names.py lists the modules.
"""
