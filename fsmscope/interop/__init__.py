"""The robotics world's files and tools: ROS bags of SMACH runs read with rosbags, MCAP written and
read with mcap, Foxglove's schemas and live protocol through foxglove-sdk (docs/interop.md).

It builds on ``fsm`` (the event schema, the log, the transcript) and knows nothing of the server or
the simulator: the CLI composes them (fsmscope/server/cli/bag_import.py, export.py, foxglove_bridge.py).
"""
