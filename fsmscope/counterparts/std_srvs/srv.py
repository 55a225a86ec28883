"""std_srvs.srv, ROS-free: Empty, Trigger and SetBool with their requests and responses."""

from fsmscope.counterparts.messages import service

Empty, EmptyRequest, EmptyResponse = service("std_srvs/Empty", {}, {})
Trigger, TriggerRequest, TriggerResponse = service("std_srvs/Trigger", {}, {"success": False, "message": ""})
SetBool, SetBoolRequest, SetBoolResponse = service("std_srvs/SetBool", {"data": False},
                                                   {"success": False, "message": ""})
