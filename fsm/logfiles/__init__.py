"""Runs on disk: the recorder (JSON Lines with snapshots and an index), the reader (tolerant of
bad lines, following, seeking), and what is made from a log: summary and SMACH's transcript."""
