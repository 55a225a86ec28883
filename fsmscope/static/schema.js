// Generated from fsm/observation/schema/ by `python -m fsmscope.server.schema_export`: do not edit by hand
// (tests/unit/test_schema_export.py fails when this file and the Python definition differ).
// One piece because it is the page's copy of that one definition: constants, rules and typedefs.

/** The event schema version this page reads. */
export const SCHEMA_VERSION = 1;

/** Every event kind. */
export const KINDS = Object.freeze(["structure", "start", "transition", "terminate", "userdata", "preempt", "error", "log", "feedback", "control", "debug", "pose", "snapshot"]);

/** Where a served machine's events come from. */
export const SOURCES = Object.freeze({"local": "local", "ingest": "ingest", "replay": "replay"});

/** A fleet overview tile's states, in the order that needs a look first. */
export const TILE_STATES = Object.freeze(["failed", "gone", "running", "idle", "done"]);

// Graph element ids: a path can hold any character; control characters and '%' are
// percent-escaped (one to one), as the server's SVG writes them.
const ESCAPED = new Map(Object.entries({"\u0000": "%00", "\u0001": "%01", "\u0002": "%02", "\u0003": "%03", "\u0004": "%04", "\u0005": "%05", "\u0006": "%06", "\u0007": "%07", "\b": "%08", "\t": "%09", "\n": "%0A", "\u000b": "%0B", "\f": "%0C", "\r": "%0D", "\u000e": "%0E", "\u000f": "%0F", "\u0010": "%10", "\u0011": "%11", "\u0012": "%12", "\u0013": "%13", "\u0014": "%14", "\u0015": "%15", "\u0016": "%16", "\u0017": "%17", "\u0018": "%18", "\u0019": "%19", "\u001a": "%1A", "\u001b": "%1B", "\u001c": "%1C", "\u001d": "%1D", "\u001e": "%1E", "\u001f": "%1F", "%": "%25", "\u007f": "%7F", "\ufffe": "%uFFFE", "\uffff": "%uFFFF"}));
const NEEDS_ESCAPE = /[\u0000\u0001\u0002\u0003\u0004\u0005\u0006\u0007\u0008\u0009\u000a\u000b\u000c\u000d\u000e\u000f\u0010\u0011\u0012\u0013\u0014\u0015\u0016\u0017\u0018\u0019\u001a\u001b\u001c\u001d\u001e\u001f\u0025\u007f\ufffe\uffff]/;

export function idText(text) {
  text = String(text);
  if (!NEEDS_ESCAPE.test(text)) return text;
  let out = "";
  for (const ch of text) out += ESCAPED.get(ch) ?? ch;
  return out;
}

export const stateId = (path) => "s:" + idText(path);
export const containerId = (path) => "c:" + idText(path);
export const outcomeId = (path, outcome) => `o:${idText(path)}:${idText(outcome)}`;
export const edgeId = (path, from, outcome) => `e:${idText(path)}:${idText(from)}:${idText(outcome)}`;

// Which of SMACH's containers a structure node is: its type when it is one of these, else (a
// user's subclass) the kind whose own field it carries, else a state machine.
const CONTAINER_TYPES = Object.freeze(["StateMachine", "Sequence", "Concurrence", "Iterator"]);
const KIND_FIELDS = Object.freeze([["outcome_map", "Concurrence"], ["exhausted_outcome", "Iterator"]]);

export function containerKind(node) {
  const type = node.type ?? "StateMachine";
  if (CONTAINER_TYPES.includes(type)) return type;
  return KIND_FIELDS.find(([field]) => field in node)?.[1] ?? "StateMachine";
}

// A machine's name (fsm/observation/names.py): 1 to MAX_NAME characters, none of / * $ ? # or a
// control character, no space at either end; valid wherever a name travels.
export const MAX_NAME = 200;
const NAME_FORBIDDEN = /[\u002f\u002a\u0024\u003f\u0023\u0000\u0001\u0002\u0003\u0004\u0005\u0006\u0007\u0008\u0009\u000a\u000b\u000c\u000d\u000e\u000f\u0010\u0011\u0012\u0013\u0014\u0015\u0016\u0017\u0018\u0019\u001a\u001b\u001c\u001d\u001e\u001f\u007f]/;

export function isMachineName(name) {
  return typeof name === "string" && name.length > 0 && [...name].length <= MAX_NAME && !name.startsWith(" ")
    && !name.endsWith(" ") && !NAME_FORBIDDEN.test(name);
}

// The words the server and the page share (fsm/observation/vocabularies.py).

/** A machine's run states. */
export const RUN_STATES = Object.freeze({"running": "running", "done": "done", "failed": "failed", "idle": "idle", "gone": "gone"});

/** The run state of a machine: `running`, `outcome` and `error` from its status, `connected` from its
 * /api/machines entry (false: its process left). Mirrors vocabularies.run_state. */
export function runState(running, outcome, error, connected) {
  if (running) return connected === false ? RUN_STATES.gone : RUN_STATES.running;
  if (outcome !== null && outcome !== undefined) return RUN_STATES.done;
  if (error !== null && error !== undefined) return RUN_STATES.failed;
  return connected === false ? RUN_STATES.gone : RUN_STATES.idle;
}

/** The kinds of the timeline's ticks: an event of one of these kinds, or a run's start (the last). */
export const TICK_KINDS = Object.freeze(["error", "preempt", "control", "debug", "run"]);

// The shapes: every event, every websocket frame, a machine's status and what it holds
// (import one with /** @typedef {import("./schema.js").NAME} NAME */).

/**
 * The whole container tree.
 * @typedef {Object} StructureEvent
 * @property {number} v schema version
 * @property {number} seq per machine, strictly increasing, never reset while the process lives
 * @property {number} t wall-clock seconds (time.time())
 * @property {(string|null)} [run] id of one top-level execution (null before the first)
 * @property {string} machine the machine's name, unique within a process or server
 * @property {"structure"} kind
 * @property {string} path the container (for feedback: the state) the event is about
 * @property {StructureNode} root the root container's node; its path is the event's path
 */

/**
 * A container began executing.
 * @typedef {Object} StartEvent
 * @property {number} v schema version
 * @property {number} seq per machine, strictly increasing, never reset while the process lives
 * @property {number} t wall-clock seconds (time.time())
 * @property {(string|null)} [run] id of one top-level execution (null before the first)
 * @property {string} machine the machine's name, unique within a process or server
 * @property {"start"} kind
 * @property {string} path the container (for feedback: the state) the event is about
 * @property {Array<string>} initial
 * @property {Array<string>} active a Concurrence: all its children
 * @property {Object<string, *>} userdata the container's whole userdata, encoded
 */

/**
 * The container's active states changed.
 * @typedef {Object} TransitionEvent
 * @property {number} v schema version
 * @property {number} seq per machine, strictly increasing, never reset while the process lives
 * @property {number} t wall-clock seconds (time.time())
 * @property {(string|null)} [run] id of one top-level execution (null before the first)
 * @property {string} machine the machine's name, unique within a process or server
 * @property {"transition"} kind
 * @property {string} path the container (for feedback: the state) the event is about
 * @property {string} from the state that returned
 * @property {string} outcome what it returned
 * @property {(string|null)} to the next state; null when a Concurrence child finished
 * @property {Array<string>} active the container's active states now
 * @property {Object<string, *>} [changes] {key: encoded value}: the keys of the container's userdata its child's step wrote (as a userdata event before it would say); absent when none
 */

/**
 * A container finished.
 * @typedef {Object} TerminateEvent
 * @property {number} v schema version
 * @property {number} seq per machine, strictly increasing, never reset while the process lives
 * @property {number} t wall-clock seconds (time.time())
 * @property {(string|null)} [run] id of one top-level execution (null before the first)
 * @property {string} machine the machine's name, unique within a process or server
 * @property {"terminate"} kind
 * @property {string} path the container (for feedback: the state) the event is about
 * @property {Array<string>} last the last active state(s)
 * @property {(string|null)} outcome null: ended without an outcome
 * @property {Array<string>} [active]
 * @property {(string|null)} [state_outcome] the outcome the last state returned
 * @property {Object<string, (string|null)>} [outcomes] a Concurrence's children's outcomes
 * @property {(string|null)} [error] 'ExceptionClass: message' when it failed
 * @property {Object<string, *>} [changes] {key: encoded value}: the keys of the container's userdata its child's step wrote (as a userdata event before it would say); absent when none
 */

/**
 * Keys of a container's userdata written since the last report of them, when no transition or terminate of the container carries them.
 * @typedef {Object} UserdataEvent
 * @property {number} v schema version
 * @property {number} seq per machine, strictly increasing, never reset while the process lives
 * @property {number} t wall-clock seconds (time.time())
 * @property {(string|null)} [run] id of one top-level execution (null before the first)
 * @property {string} machine the machine's name, unique within a process or server
 * @property {"userdata"} kind
 * @property {string} path the container (for feedback: the state) the event is about
 * @property {Object<string, *>} changes {key: encoded value}
 */

/**
 * A preempt was requested of, or serviced by, the state at path.
 * @typedef {Object} PreemptEvent
 * @property {number} v schema version
 * @property {number} seq per machine, strictly increasing, never reset while the process lives
 * @property {number} t wall-clock seconds (time.time())
 * @property {(string|null)} [run] id of one top-level execution (null before the first)
 * @property {string} machine the machine's name, unique within a process or server
 * @property {"preempt"} kind
 * @property {string} path the container (for feedback: the state) the event is about
 * @property {("requested"|"serviced")} phase
 */

/**
 * A state raised, or a container failed.
 * @typedef {Object} ErrorEvent
 * @property {number} v schema version
 * @property {number} seq per machine, strictly increasing, never reset while the process lives
 * @property {number} t wall-clock seconds (time.time())
 * @property {(string|null)} [run] id of one top-level execution (null before the first)
 * @property {string} machine the machine's name, unique within a process or server
 * @property {"error"} kind
 * @property {string} path the container (for feedback: the state) the event is about
 * @property {(string|null)} state the child that raised
 * @property {string} exc_type the root cause's class
 * @property {string} message
 * @property {string} [traceback] the whole chain
 * @property {string} [wrapped_as] the SMACH exception that carried it
 */

/**
 * A log line the other events do not already say.
 * @typedef {Object} LogEvent
 * @property {number} v schema version
 * @property {number} seq per machine, strictly increasing, never reset while the process lives
 * @property {number} t wall-clock seconds (time.time())
 * @property {(string|null)} [run] id of one top-level execution (null before the first)
 * @property {string} machine the machine's name, unique within a process or server
 * @property {"log"} kind
 * @property {string} path the container (for feedback: the state) the event is about
 * @property {("debug"|"info"|"warn"|"error")} level
 * @property {string} msg
 */

/**
 * Action feedback received by a SimpleActionState.
 * @typedef {Object} FeedbackEvent
 * @property {number} v schema version
 * @property {number} seq per machine, strictly increasing, never reset while the process lives
 * @property {number} t wall-clock seconds (time.time())
 * @property {(string|null)} [run] id of one top-level execution (null before the first)
 * @property {string} machine the machine's name, unique within a process or server
 * @property {"feedback"} kind
 * @property {string} path the container (for feedback: the state) the event is about
 * @property {string} action the action's name
 * @property {*} feedback encoded
 */

/**
 * Somebody asked the machine to do something.
 * @typedef {Object} ControlEvent
 * @property {number} v schema version
 * @property {number} seq per machine, strictly increasing, never reset while the process lives
 * @property {number} t wall-clock seconds (time.time())
 * @property {(string|null)} [run] id of one top-level execution (null before the first)
 * @property {string} machine the machine's name, unique within a process or server
 * @property {"control"} kind
 * @property {string} path the container (for feedback: the state) the event is about
 * @property {string} action preempt, initial-state, start, publish, ...
 * @property {(string|null)} [reason] the operator's words
 * @property {string} client who asked: an address, the role and the page ('127.0.0.1 (operator, page 3f2a9c1d)'), or 'deadman'
 * @property {string} result 'accepted' or why not
 * @property {Object<string, *>} [params] what was asked
 */

/**
 * The debugger (fsm.debugging) changed mode, held or released a transition, forced an outcome or replaced its breakpoints; path is the container's (the root's for mode and breakpoints).
 * @typedef {Object} DebugEvent
 * @property {number} v schema version
 * @property {number} seq per machine, strictly increasing, never reset while the process lives
 * @property {number} t wall-clock seconds (time.time())
 * @property {(string|null)} [run] id of one top-level execution (null before the first)
 * @property {string} machine the machine's name, unique within a process or server
 * @property {"debug"} kind
 * @property {string} path the container (for feedback: the state) the event is about
 * @property {("mode"|"hold"|"release"|"forced"|"breakpoints")} action
 * @property {("run"|"pause"|"step")} [mode] mode: what it is now
 * @property {(string|null)} [level] mode step: the container whose next transition ends the step (null: the next anywhere)
 * @property {string} [state] hold, release, forced: the child's label
 * @property {("before"|"after")} [at] hold, release: before the child runs, or after it returned (the transition held)
 * @property {(string|null)} [outcome] hold: the outcome to be taken; release, forced: the one taken
 * @property {(string|null)} [returned] forced: what the state returned (null: it did not run)
 * @property {("pause"|"step"|"breakpoint")} [reason] hold: why
 * @property {string} [detail] hold: in words ('hit breakpoint before PICK/CLOSE when ...')
 * @property {(string|null)} [by] mode, forced, breakpoints: who asked; release: what ended the hold (resume, step, force, preempt, shutdown, detach)
 * @property {Array<Breakpoint>} [breakpoints] breakpoints: the whole set
 */

/**
 * The robot's pose, sampled at the rate the 3D view draws it (the demo: 30 Hz).
 * @typedef {Object} PoseEvent
 * @property {number} v schema version
 * @property {number} seq per machine, strictly increasing, never reset while the process lives
 * @property {number} t wall-clock seconds (time.time())
 * @property {(string|null)} [run] id of one top-level execution (null before the first)
 * @property {string} machine the machine's name, unique within a process or server
 * @property {"pose"} kind
 * @property {string} path the container (for feedback: the state) the event is about
 * @property {Object<string, number>} joints joint positions by joint name (radians, metres)
 * @property {Object<string, Array<number>>} [bodies] free bodies' poses by name: [x, y, z, qw, qx, qy, qz] in the world frame
 */

/**
 * The full rebuilt state of one machine at seq.
 * @typedef {Object} SnapshotEvent
 * @property {number} v schema version
 * @property {number} seq per machine, strictly increasing, never reset while the process lives
 * @property {number} t wall-clock seconds (time.time())
 * @property {(string|null)} [run] id of one top-level execution (null before the first)
 * @property {string} machine the machine's name, unique within a process or server
 * @property {"snapshot"} kind
 * @property {string} path the container (for feedback: the state) the event is about
 * @property {MachineStatus} status the machine's state after the event seq
 */

/** @typedef {StructureEvent|StartEvent|TransitionEvent|TerminateEvent|UserdataEvent|PreemptEvent|ErrorEvent|LogEvent|FeedbackEvent|ControlEvent|DebugEvent|PoseEvent|SnapshotEvent} FsmEvent */

/**
 * The machine's whole state: the first frame of a stream (unless it resumes), and again after missed (server to page).
 * @typedef {Object} SnapshotFrame
 * @property {"snapshot"} type
 * @property {MachineStatus} status the machine's status with its structure (docs/events.md)
 * @property {number} last_seq the seq of the last event the status includes
 * @property {History} [history] a new connection's only: the current run's events up to last_seq, for the log (already in the status: not to be applied again)
 */

/**
 * Events in seq order: one per frame while the page keeps up, every event of the last 20 ms under a flood, or of the page's pace (server to page).
 * @typedef {Object} EventsFrame
 * @property {"events"} type
 * @property {Array<FsmEvent>} events
 */

/**
 * The page fell behind and this many events were dropped for it; a snapshot follows (server to page).
 * @typedef {Object} MissedFrame
 * @property {"missed"} type
 * @property {number} count
 */

/**
 * At most one frame every ms from now on, each with every event since the one before (0: each as it comes) (page to server).
 * @typedef {Object} PaceFrame
 * @property {"pace"} type
 * @property {number} ms
 */

/**
 * The fleet overview's tiles (GET /api/overview's), at most twice a second, when a tile changed (server to page).
 * @typedef {Object} OverviewFrame
 * @property {"overview"} type
 * @property {number} now the server's clock
 * @property {Array<Tile>} tiles as GET /api/overview
 */

/**
 * Which of its machines take controls (and may be started again): first on each connection, again when a machine is attached; each replaces the last (publisher to server).
 * @typedef {Object} HelloFrame
 * @property {"hello"} type
 * @property {Array<string>} controllable machine names
 * @property {Object<string, boolean>} can_start {name: whether it may be started again}
 */

/**
 * A REST control of one of its machines (docs/api.md) (server to publisher).
 * @typedef {Object} ControlFrame
 * @property {"control"} type
 * @property {number} id its answer carries it
 * @property {string} machine
 * @property {string} action what to do (below)
 * @property {Object<string, *>} params the action's (below)
 * @property {string} client who asked
 */

/**
 * The result of a control (publisher to server).
 * @typedef {Object} AnswerFrame
 * @property {"answer"} type
 * @property {number} id the control's
 * @property {number} status 200/202, or the 4xx the request answers
 * @property {number} [seq] of the control event it caused
 * @property {string} [detail] why not
 * @property {Array<Breakpoint>} [breakpoints] breakpoints, get-breakpoints: the whole set
 */

/**
 * The operator lease of one of its machines was taken, released or lapsed; sent again when the publisher reconnects (server to publisher).
 * @typedef {Object} LeaseFrame
 * @property {"lease"} type
 * @property {string} machine
 * @property {boolean} held
 * @property {number} after seconds
 * @property {("pause"|"preempt"|"none")} action while it is held, what the publisher does itself when its link is gone that long
 */

/**
 * An event refused at the door (server to publisher).
 * @typedef {Object} RejectedFrame
 * @property {"rejected"} type
 * @property {string} reason what is wrong, in words
 * @property {*} machine the event's, if any
 * @property {*} seq the event's, if any
 */

/** @typedef {SnapshotFrame|EventsFrame|MissedFrame|PaceFrame|OverviewFrame|HelloFrame|ControlFrame|AnswerFrame|LeaseFrame|RejectedFrame} Frame */

/**
 * A breakpoint.
 * @typedef {Object} Breakpoint
 * @property {string} state the state's path
 * @property {("before"|"after")} at
 * @property {(string|null)} outcome after: only this outcome
 * @property {(string|null)} when a condition over the container's userdata
 */

/**
 * A container status.
 * @typedef {Object} ContainerStatus
 * @property {Array<string>} active active children's labels
 * @property {Array<string>} initial initial children's labels
 * @property {Object<string, *>} userdata its userdata, encoded
 * @property {boolean} running
 * @property {(string|null)} outcome its last outcome
 * @property {(LastTransition|null)} [last] its last transition in this run: {from, outcome, to, seq}
 * @property {Object<string, Object<string, *>>} [changes] the keys its last transition wrote: {key: {old (absent: a new key), new}}
 * @property {boolean} [written] its userdata was written since its last transition
 */

/**
 * A debugger's state.
 * @typedef {Object} DebugState
 * @property {("run"|"pause"|"step")} mode
 * @property {(string|null)} level
 * @property {Array<Hold>} holds {path, state, at, outcome, reason, detail, seq}
 * @property {Array<Breakpoint>} breakpoints {state, at, outcome, when}
 */

/**
 * A history (below).
 * @typedef {Object} History
 * @property {boolean} complete whether it reaches back to the run's first event
 * @property {Array<FsmEvent>} events oldest first, at most 5000
 */

/**
 * A hold.
 * @typedef {Object} Hold
 * @property {string} path the holding container's
 * @property {string} state
 * @property {("before"|"after")} at
 * @property {(string|null)} outcome
 * @property {string} reason
 * @property {string} detail
 * @property {number} seq the hold event's
 */

/**
 * A transition.
 * @typedef {Object} LastTransition
 * @property {string} from the state that returned
 * @property {string} outcome
 * @property {(string|null)} to the next state, or the container's outcome when it ended
 * @property {number} seq the event's
 */

/**
 * A machine status (fsm.observation.status.Status.to_dict()).
 * @typedef {Object} MachineStatus
 * @property {string} [machine] its name
 * @property {(string|null)} [run] the current (or last) run
 * @property {(string|null)} [root_path]
 * @property {(StructureNode|null)} [structure]
 * @property {Object<string, ContainerStatus>} containers
 * @property {boolean} running the root is running
 * @property {(string|null)} outcome the root's last outcome
 * @property {(Object<string, *>|null)} [error] the last error event's fields
 * @property {number} [last_seq]
 * @property {(number|null)} [last_t]
 * @property {number} [run_seq] the seq of the current run's first event
 * @property {(PendingPreempt|null)} [preempt] a preempt requested and not over yet (below)
 * @property {(Pose|null)} [pose] the robot's last recorded pose: {seq, t, joints, bodies}
 * @property {(DebugState|null)} [debug] null until a debug event: {mode, level, holds, breakpoints} (below)
 */

/**
 * A pending preempt.
 * @typedef {Object} PendingPreempt
 * @property {number} seq the preempt event's
 * @property {number} t when it was requested
 * @property {string} path of the container it was requested of
 * @property {Array<string>} serviced paths of the states that serviced it so far
 */

/**
 * A pose.
 * @typedef {Object} Pose
 * @property {number} seq the pose event's
 * @property {number} t
 * @property {Object<string, number>} joints
 * @property {Object<string, Array<number>>} [bodies]
 */

/**
 * A structure node (below).
 * @typedef {Object} StructureNode
 * @property {string} label the name its parent knows it by
 * @property {string} path its parent's path, '/', its label
 * @property {string} type the class name (StateMachine, Concurrence, CBState, ...)
 * @property {boolean} container whether it holds children
 * @property {Array<string>} outcomes registered outcomes, sorted
 * @property {Array<string>} input_keys sorted
 * @property {Array<string>} output_keys sorted
 * @property {Object<string, string>} remapping its parent's remapping for it: {its key: the parent's key}
 * @property {string} [doc] the first paragraph of its class's docstring (at most 500 characters); absent when the class has none or is one of fsm's own
 * @property {Array<string>} [initial] a container's: initial states
 * @property {Array<Transition>} [transitions] a container's: its edges (below)
 * @property {Array<StructureNode>} [children] a container's: nodes, in add order
 * @property {(string|null)} [default_outcome] a container's: a Concurrence's
 * @property {Object<string, Object<string, string>>} [outcome_map] a container's: a Concurrence's {container outcome: {child: outcome}}
 */

/**
 * A fleet overview tile.
 * @typedef {Object} Tile
 * @property {string} name the dashboard's name of the machine (a robot's: robot:machine)
 * @property {(string|null)} robot the robot publishing it on Zenoh (null for the others)
 * @property {string} machine its name on its robot (its name, for the others)
 * @property {("local"|"ingest"|"replay")} source where its events come from (GET /api/machines' source)
 * @property {("failed"|"gone"|"running"|"idle"|"done")} state failed: its run ended on an error; gone: its process went away while it ran or idled; done: it reached an outcome
 * @property {(string|null)} outcome the outcome its run reached
 * @property {(string|null)} error the exception type of a failed run
 * @property {Array<string>} active the full paths of its active states (leaves)
 * @property {number} rate events per second over the last 5 s, as the server received them
 * @property {number} last_seq its newest event's
 * @property {(number|null)} last_seen when the server saw its newest event (Unix time, the server's clock; null before any)
 * @property {boolean} connected false when the process that publishes it has gone away
 */

/**
 * A transition.
 * @typedef {Object} Transition
 * @property {string} from a child's label
 * @property {string} outcome one of its outcomes
 * @property {(string|null)} to a child's label, a container outcome, or null (the container outcome of the same name)
 */
