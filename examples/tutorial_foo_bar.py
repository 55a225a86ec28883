#!/usr/bin/env python
"""SMACH's first tutorial, a ROS 1 script as its users write it: FOO returns outcome1 three times,
then outcome2, which ends the machine in outcome4; BAR returns outcome2, back to FOO.

It runs on ROS 1 with the original smach and smach_ros (``python tutorial_foo_bar.py`` beside a
roscore), and unchanged under ``fsmscope run examples/tutorial_foo_bar.py``: on the original smach where
it is installed, otherwise on fsm with ROS-free rospy and smach_ros (docs/guide.md, "Unchanged SMACH
scripts"). Unlike the tutorial it does not end in ``rospy.spin()``: fsmscope run keeps showing the
machine after the script ends.
"""

import rospy
import smach
import smach_ros


# define state Foo
class Foo(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=['outcome1', 'outcome2'])
        self.counter = 0

    def execute(self, userdata):
        rospy.loginfo('Executing state FOO')
        if self.counter < 3:
            self.counter += 1
            return 'outcome1'
        else:
            return 'outcome2'


# define state Bar
class Bar(smach.State):
    def __init__(self):
        smach.State.__init__(self, outcomes=['outcome2'])

    def execute(self, userdata):
        rospy.loginfo('Executing state BAR')
        return 'outcome2'


def main():
    rospy.init_node('smach_example_state_machine')

    # Create a SMACH state machine
    sm = smach.StateMachine(outcomes=['outcome4', 'outcome5'])

    # Open the container
    with sm:
        # Add states to the container
        smach.StateMachine.add('FOO', Foo(),
                               transitions={'outcome1': 'BAR',
                                            'outcome2': 'outcome4'})
        smach.StateMachine.add('BAR', Bar(),
                               transitions={'outcome2': 'FOO'})

    # Create and start the introspection server
    sis = smach_ros.IntrospectionServer('server_name', sm, '/SM_ROOT')
    sis.start()

    # Execute SMACH plan
    outcome = sm.execute()
    rospy.loginfo('The state machine ended in %s' % outcome)
    sis.stop()


if __name__ == '__main__':
    main()
