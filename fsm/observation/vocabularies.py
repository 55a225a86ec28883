"""The words the server and the page share beyond the events' fields, defined once: a machine's run
state (what the dashboard's pill and picker and the fleet's tiles say) and the kinds of the
timeline's ticks. ``fsmscope/static/schema.js`` carries them to the page (``python -m server.schema_export``,
with ``runState``, the page's mirror of ``run_state``: tests/unit/test_vocabularies.py runs both).

Standard library only, like the rest of ``fsm``.
"""

from __future__ import annotations

RUNNING, DONE, FAILED, IDLE, GONE = RUN_STATES = ("running", "done", "failed", "idle", "gone")


def run_state(running: bool, outcome: str | None, error: object, connected: bool | None) -> str:
    """running; done (its run reached an outcome) or failed (it ended without one after an error);
    idle (not started, or ended with neither); gone: another process's machine whose process left
    (``connected`` False) while it ran or idled, so nobody can tell what it does now. A run that
    ended stays done or failed when its process goes."""
    if running:
        return GONE if connected is False else RUNNING
    if outcome is not None:
        return DONE
    if error is not None:
        return FAILED
    return GONE if connected is False else IDLE


# The timeline's ticks (fsmscope/server/timeline.py): an event of one of these kinds, or a run's start.
EVENT_TICK_KINDS = ("error", "preempt", "control", "debug")
RUN_TICK = "run"
TICK_KINDS = EVENT_TICK_KINDS + (RUN_TICK,)
