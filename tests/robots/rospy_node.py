"""A small rospy node for the tests of fsmscope's ROS 1 client (tests/ros1/test_ros1_wire.py), run by
Debian's Python with rospy and smach_msgs' generated classes (tests/rospy_support.py):

    rospy_node.py NAME status TOPIC      publishes SmachContainerStatus 20 times a second, counting in `info`
    rospy_node.py NAME broken TOPIC      publishes SmachContainerStatus, every other message cut short
    rospy_node.py NAME string TOPIC      publishes std_msgs/String (another type on a smach_msgs name)
    rospy_node.py NAME echo TOPIC TYPE   prints each message of TYPE (pkg/Type) as a JSON line
    rospy_node.py NAME smach SERVER      runs an original SMACH machine (A -> B -> A ...) that
                                         smach_ros's own IntrospectionServer SERVER introspects

It prints ``ready`` once its publisher or subscriber exists, and runs until it is killed.
"""
import base64
import io
import json
import pickle
import sys
import threading

import genpy
import roslib.message
import rospy
from smach_msgs.msg import SmachContainerStatus
from std_msgs.msg import String

STAMP = rospy.Time(1700000000, 250000000)
USERDATA = base64.b64encode(pickle.dumps({"rounds": 3}, 2)).decode()  # as smach_ros puts it in local_data


def status(number):
    message = SmachContainerStatus(path="/SM_ROOT", initial_states=["INIT"], active_states=["STEP_%d" % number],
                                   local_data=USERDATA, info=str(number))
    message.header.stamp = STAMP
    return message


class Raw(rospy.AnyMsg):
    """Bytes sent as they are, announced as SmachContainerStatus with its real md5sum."""

    _type = SmachContainerStatus._type
    _md5sum = SmachContainerStatus._md5sum
    _full_text = SmachContainerStatus._full_text


def plain(value):
    if isinstance(value, genpy.Message):
        return {slot: plain(getattr(value, slot)) for slot in value.__slots__}
    if isinstance(value, genpy.TVal):
        return value.to_sec()
    if isinstance(value, (list, tuple)):
        return [plain(item) for item in value]
    if isinstance(value, bytes):
        return base64.b64encode(value).decode()
    return value


def echo(message):
    print(json.dumps(plain(message)), flush=True)


def run_smach(server):
    import smach
    import smach_ros

    class Step(smach.State):
        def __init__(self):
            smach.State.__init__(self, outcomes=["next"])

        def execute(self, userdata):
            rospy.sleep(0.1)
            return "next"

    machine = smach.StateMachine(outcomes=["never"])
    with machine:
        smach.StateMachine.add("A", Step(), transitions={"next": "B"})
        smach.StateMachine.add("B", Step(), transitions={"next": "A"})
    smach_ros.IntrospectionServer(server, machine, "/SM_ROOT").start()
    threading.Thread(target=machine.execute, daemon=True).start()
    print("ready", flush=True)
    rospy.spin()


def main(name, mode, topic, *rest):
    rospy.init_node(name.lstrip("/"))
    rate = rospy.Rate(20)
    number = 0
    if mode == "smach":
        run_smach(topic)
    elif mode == "echo":
        rospy.Subscriber(topic, roslib.message.get_message_class(rest[0]), echo)
        print("ready", flush=True)
        rospy.spin()
    elif mode == "string":
        publisher = rospy.Publisher(topic, String, queue_size=10)
        print("ready", flush=True)
        while not rospy.is_shutdown():
            publisher.publish(String(data="not a status"))
            rate.sleep()
    else:
        publisher = rospy.Publisher(topic, Raw if mode == "broken" else SmachContainerStatus, queue_size=100)
        print("ready", flush=True)
        while not rospy.is_shutdown():
            if mode == "broken":
                buffer = io.BytesIO()
                status(number).serialize(buffer)
                whole = buffer.getvalue()
                message = Raw()
                message._buff = whole if number % 2 == 0 else whole[:len(whole) // 2]
            else:
                message = status(number)
            publisher.publish(message)
            number += 1
            rate.sleep()


if __name__ == "__main__":
    main(*sys.argv[1:])
