#!/usr/bin/env python
"""SMACH's ROS states, a ROS 1 script as its users write it: STATE1 is a ServiceState that calls the
``enable`` service (std_srvs/SetBool) and aborts unless it answers success; STATE2 is a
SimpleActionState that sends userdata's ``a`` and ``b`` to the ``add_two_ints`` action
(actionlib/TwoInts, the test action actionlib ships) and stores its result's ``sum`` in userdata.
The script serves both itself, with rospy.Service and actionlib.SimpleActionServer.

It runs on ROS 1 (the message types are Debian 12's python3-std-srvs and python3-actionlib), and
unchanged under ``fsmscope run examples/tutorial_service_action.py``: on the original smach where it
is installed, otherwise on fsm with ROS-free rospy, smach_ros, actionlib and those messages
(docs/guide.md, "Unchanged SMACH scripts").
"""

import actionlib
import rospy
import smach
import smach_ros
from actionlib.msg import TwoIntsAction, TwoIntsResult
from std_srvs.srv import SetBool, SetBoolRequest, SetBoolResponse


def handle_enable(request):
    rospy.loginfo('enable service called with data=%s' % request.data)
    return SetBoolResponse(success=True, message='enabled' if request.data else 'disabled')


# A trivial action server: adds the goal's two ints
class AddTwoIntsServer(object):
    def __init__(self, name):
        self._sas = actionlib.SimpleActionServer(name, TwoIntsAction, execute_cb=self.execute_cb,
                                                 auto_start=False)
        self._sas.start()

    def execute_cb(self, goal):
        rospy.sleep(0.1)
        if self._sas.is_preempt_requested():
            self._sas.set_preempted()
        else:
            self._sas.set_succeeded(TwoIntsResult(sum=goal.a + goal.b))


def enable_response_cb(userdata, response):
    if not response.success:
        return 'aborted'


def main():
    rospy.init_node('smach_example_service_action')

    # Start the service and the action server the states call
    rospy.Service('enable', SetBool, handle_enable)
    AddTwoIntsServer('add_two_ints')

    # Create a SMACH state machine
    sm = smach.StateMachine(outcomes=['succeeded', 'aborted', 'preempted'])
    sm.userdata.a = 2
    sm.userdata.b = 3

    # Open the container
    with sm:
        # STATE1 calls the enable service with a fixed request
        smach.StateMachine.add('STATE1',
                               smach_ros.ServiceState('enable', SetBool,
                                                      request=SetBoolRequest(data=True),
                                                      response_cb=enable_response_cb),
                               transitions={'succeeded': 'STATE2'})

        # STATE2 sends a goal made of the userdata's a and b, and keeps the result's sum
        smach.StateMachine.add('STATE2',
                               smach_ros.SimpleActionState('add_two_ints', TwoIntsAction,
                                                           goal_slots=['a', 'b'],
                                                           result_slots=['sum']),
                               transitions={'succeeded': 'succeeded'})

    # Create and start the introspection server
    sis = smach_ros.IntrospectionServer('server_name', sm, '/SM_ROOT')
    sis.start()

    # Execute SMACH plan
    outcome = sm.execute()
    rospy.loginfo('The state machine ended in %s with sum=%s' % (outcome, sm.userdata.sum))
    sis.stop()
    rospy.signal_shutdown('All done.')


if __name__ == '__main__':
    main()
