"""actionlib_msgs.msg's GoalStatus, ROS-free: its status numbers (a SimpleActionState's result_cb
is given one) and its fields, status and text."""

from fsmscope.counterparts.messages import message

GoalStatus = message("actionlib_msgs/GoalStatus", status=0, text="")
for _number, _name in enumerate(("PENDING", "ACTIVE", "PREEMPTED", "SUCCEEDED", "ABORTED", "REJECTED",
                                 "PREEMPTING", "RECALLING", "RECALLED", "LOST")):
    setattr(GoalStatus, _name, _number)
