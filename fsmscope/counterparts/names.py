"""Which ROS names the counterparts cover, and the words for one they do not."""

from __future__ import annotations

from typing import Iterable

# Each name a script imports -> the file or folder (under fsmscope/counterparts/) that stands in for it.
COVERED = {
    "smach": "smach.py",
    "smach_ros": "smach_ros.py",
    "rospy": "rospy.py",
    "roslib": "roslib.py",
    "actionlib": "actionlib",
    "actionlib_msgs": "actionlib_msgs",
    "std_msgs": "std_msgs",
    "std_srvs": "std_srvs",
}

# ROS 1 and ROS 2 Python packages a SMACH script may import that have no counterpart; with any
# name ending in _msgs, _srvs or _actions, an import of one that is not installed says so.
ROS_PACKAGES = frozenset((
    "rosgraph", "rospkg", "rosparam", "rosservice", "rostopic", "rosnode", "roslaunch", "rosbag", "genpy",
    "genmsg", "tf", "tf2_ros", "tf2_py", "tf_conversions", "message_filters", "dynamic_reconfigure",
    "cv_bridge", "image_geometry", "interactive_markers", "moveit_commander", "smach_viewer", "rclpy",
    "launch", "launch_ros", "ament_index_python",
))
GUIDE = "docs/guide.md, 'Unchanged SMACH scripts'"


def is_ros_package(top: str) -> bool:
    return top in ROS_PACKAGES or top.endswith(("_msgs", "_srvs", "_actions"))


def missing_module(name: str, original: str | None) -> ModuleNotFoundError:
    """The error for a ROS module ``name`` that is not installed: on fsm (``original`` None), one
    that has no counterpart; beside the original smach (at ``original``), any."""
    if original is None:
        why = ("smach is not installed, so fsmscope runs this script on fsm without ROS, and has no ROS-free "
               "counterpart of %r (it has %s; %s)" % (name, ", ".join(sorted(COVERED)), GUIDE))
    else:
        why = ("smach is installed (%s), so fsmscope runs this script on it as it is, with what is installed "
               "beside it, and %r is not (%s)" % (original, name, GUIDE))
    return ModuleNotFoundError("No module named %r: %s" % (name, why), name=name)


def not_covered(module: str, attribute: str, covered: Iterable[str]) -> AttributeError:
    """The error for ``module.attribute`` that the counterpart of ``module`` does not offer."""
    return AttributeError("%s.%s: fsmscope runs this script without ROS, and its ROS-free %s has no %s "
                          "(it has %s; %s)" % (module, attribute, module, attribute, ", ".join(sorted(covered)), GUIDE),
                          name=attribute)
