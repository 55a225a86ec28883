"""std_msgs.msg's plain types, ROS-free: Empty, Bool, String, Int32, Int64, Float32, Float64."""

from fsmscope.counterparts.messages import message

Empty = message("std_msgs/Empty")
Bool = message("std_msgs/Bool", data=False)
String = message("std_msgs/String", data="")
Int32 = message("std_msgs/Int32", data=0)
Int64 = message("std_msgs/Int64", data=0)
Float32 = message("std_msgs/Float32", data=0.0)
Float64 = message("std_msgs/Float64", data=0.0)
