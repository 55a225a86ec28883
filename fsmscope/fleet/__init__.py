"""A fleet of robots' machines over Zenoh (eclipse-zenoh): each robot process publishes its machines
(robot.py), a dashboard discovers and follows them (watcher.py), on the key space keys.py names
(docs/fleet.md).

Like fsmscope/server/publisher.py it runs in the robot's process: the standard library, ``zenoh`` and
``fsm`` only, nothing of the server.
"""
