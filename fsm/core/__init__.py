"""The SMACH core: states, containers (StateMachine, Concurrence, Sequence, Iterator), userdata, logging.

Knows nothing of ROS's counterparts, log files or observers, and imports nothing outside itself: it
reports every step through its own seam, ``fsm.core.reporting``, which ``fsm.observation`` implements
when something listens.
"""
