"""What the ROS 1 test robots' states share (tests/robots/ros1_robot.py, smach_ros_loop.py): work for a
while of ROS time, as a robot's action does, and stop as soon as a preempt is asked."""
import rospy
import smach


class Timed(smach.State):
    """Works ``seconds`` of ROS time, then returns ``done(ud)``; 'preempted' as soon as it is asked to."""

    def __init__(self, seconds, outcomes, **keys):
        smach.State.__init__(self, outcomes + ["preempted"], **keys)
        self.seconds = seconds

    def execute(self, ud):
        end = rospy.get_time() + self.seconds
        while rospy.get_time() < end:
            if self.preempt_requested():
                self.service_preempt()
                return "preempted"
            rospy.sleep(0.02)
        return self.done(ud)
