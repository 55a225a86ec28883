"""The status shape: what ``fsm.observation.status.Status.to_dict()`` holds (a snapshot's ``status``,
GET .../status), with the debugger's state, its holds and breakpoints, the pending preempt and the pose."""

from __future__ import annotations

from .fields import (BOOL, LIST_STR, MAP_BODY_POSE, MAP_NUMBER, NAME, NUMBER, OBJECT, OPT_NUMBER, OPT_STR, PATH, SEQ,
                     STR, Field, list_of, nullable, object_of, one_of, shape)
from .tree import NODE

DEBUG_ACTIONS = ("mode", "hold", "release", "forced", "breakpoints")
DEBUG_MODES = ("run", "pause", "step")
POSITIONS = ("before", "after")  # where a breakpoint or a hold is: before a state runs, after it returned
AT = one_of(*POSITIONS)

LAST_TRANSITION_FIELDS = (Field("from", STR, doc="the state that returned"), Field("outcome", STR),
                          Field("to", OPT_STR, doc="the next state, or the container's outcome when it ended"),
                          Field("seq", SEQ, doc="the event's"))
CONTAINER_STATUS_FIELDS = (Field("active", LIST_STR, doc="active children's labels"),
                           Field("initial", LIST_STR, doc="initial children's labels"),
                           Field("userdata", OBJECT, doc="its userdata, encoded"),
                           Field("running", BOOL), Field("outcome", OPT_STR, doc="its last outcome"),
                           Field("last", nullable(shape("a transition", "LastTransition", LAST_TRANSITION_FIELDS)),
                                 required=False, doc="its last transition in this run: {from, outcome, to, seq}"),
                           Field("changes", object_of(OBJECT, "an object of {old, new} objects"), required=False,
                                 doc="the keys its last transition wrote: {key: {old (absent: a new key), new}}"),
                           Field("written", BOOL, required=False,
                                 doc="its userdata was written since its last transition"))
BREAKPOINT_FIELDS = (Field("state", PATH, doc="the state's path"), Field("at", AT),
                     Field("outcome", OPT_STR, doc="after: only this outcome"),
                     Field("when", OPT_STR, doc="a condition over the container's userdata"))
BREAKPOINT = shape("a breakpoint", "Breakpoint", BREAKPOINT_FIELDS)
HOLD_FIELDS = (Field("path", PATH, doc="the holding container's"), Field("state", STR), Field("at", AT),
               Field("outcome", OPT_STR), Field("reason", STR), Field("detail", STR),
               Field("seq", SEQ, doc="the hold event's"))
DEBUG_STATUS_FIELDS = (Field("mode", one_of(*DEBUG_MODES)), Field("level", nullable(PATH)),
                       Field("holds", list_of(shape("a hold", "Hold", HOLD_FIELDS), "a list of holds"),
                             doc="{path, state, at, outcome, reason, detail, seq}"),
                       Field("breakpoints", list_of(BREAKPOINT, "a list of breakpoints"), doc="{state, at, outcome, when}"))
POSE_FIELDS = (Field("seq", SEQ, doc="the pose event's"), Field("t", NUMBER),
               Field("joints", MAP_NUMBER), Field("bodies", MAP_BODY_POSE, required=False))
PREEMPT_FIELDS = (Field("seq", SEQ, doc="the preempt event's"), Field("t", NUMBER, doc="when it was requested"),
                  Field("path", PATH, doc="of the container it was requested of"),
                  Field("serviced", LIST_STR, doc="paths of the states that serviced it so far"))
STATUS_FIELDS = (
    Field("machine", NAME, required=False, doc="its name"),
    Field("run", OPT_STR, required=False, doc="the current (or last) run"),
    Field("root_path", nullable(PATH), required=False), Field("structure", nullable(NODE), required=False),
    Field("containers", object_of(shape("a container status", "ContainerStatus", CONTAINER_STATUS_FIELDS),
                                  "an object of container statuses")),
    Field("running", BOOL, doc="the root is running"), Field("outcome", OPT_STR, doc="the root's last outcome"),
    Field("error", nullable(OBJECT), required=False, doc="the last error event's fields"),
    Field("last_seq", SEQ, required=False), Field("last_t", OPT_NUMBER, required=False),
    Field("run_seq", SEQ, required=False, doc="the seq of the current run's first event"),
    Field("preempt", nullable(shape("a pending preempt", "PendingPreempt", PREEMPT_FIELDS)),
          required=False, doc="a preempt requested and not over yet (below)"),
    Field("pose", nullable(shape("a pose", "Pose", POSE_FIELDS)), required=False,
          doc="the robot's last recorded pose: {seq, t, joints, bodies}"),
    Field("debug", nullable(shape("a debugger's state", "DebugState", DEBUG_STATUS_FIELDS)),
          required=False, doc="null until a debug event: {mode, level, holds, breakpoints} (below)"),
)
STATUS = shape("a machine status (fsm.observation.status.Status.to_dict())", "MachineStatus", STATUS_FIELDS)
