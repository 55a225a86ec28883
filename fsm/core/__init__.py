"""The SMACH core: states, containers (StateMachine, Concurrence, Sequence, Iterator), userdata, logging.

Knows nothing of ROS's counterparts or of log files; it reports every step through
``fsm.observation.introspection`` when something listens.
"""
