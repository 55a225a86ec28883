"""Events for the tests that feed them in from outside: well-formed ones built with the schema's
builder, and a structure of any depth."""

from __future__ import annotations

from fsm.observation import schema


def ev(seq: int, kind: str, path: str = "/SM_ROOT", machine: str = "m", run: str = "r1", **fields) -> dict:
    return schema.event(seq, 1000.0 + seq, run, machine, kind, path, fields)


def leaf(label: str, parent: str) -> dict:
    return {"label": label, "path": parent + "/" + label, "type": "CBState", "container": False,
            "outcomes": ["go"], "input_keys": [], "output_keys": [], "remapping": {}}


def container(label: str, path: str, children: list[dict], transitions: list[dict] | None = None) -> dict:
    return {"label": label, "path": path, "type": "StateMachine", "container": True, "outcomes": ["done"],
            "input_keys": [], "output_keys": [], "remapping": {},
            "initial": [children[0]["label"]] if children else [], "children": children,
            "transitions": transitions or []}


def flat_root(*labels: str) -> dict:
    """/SM_ROOT holding the given leaves, each going to the next, the last to 'done'."""
    children = [leaf(label, "/SM_ROOT") for label in labels]
    transitions = [{"from": a, "outcome": "go", "to": b} for a, b in zip(labels, labels[1:])]
    transitions.append({"from": labels[-1], "outcome": "go", "to": "done"})
    return container("SM_ROOT", "/SM_ROOT", children, transitions)


def deep_root(levels: int) -> dict:
    """A chain of ``levels`` nested StateMachines under /SM_ROOT, a leaf at the bottom."""
    paths = ["/SM_ROOT"]
    for i in range(levels):
        paths.append(paths[-1] + "/L%d" % i)
    node = leaf("A", paths[-1])
    for path in reversed(paths):
        node = container(path.rsplit("/", 1)[-1], path, [node], [{"from": node["label"], "outcome": "done"
                                                                  if node["container"] else "go", "to": "done"}])
    return node


def run_of(root: dict, machine: str = "m") -> list[dict]:
    """A valid run: structure, start, every state in turn, terminate."""
    labels = [c["label"] for c in root["children"]]
    events = [ev(1, "structure", machine=machine, root=root),
              ev(2, "start", machine=machine, initial=labels[:1], active=labels[:1], userdata={})]
    seq = 3
    for a, b in zip(labels, labels[1:]):
        events.append(ev(seq, "transition", machine=machine, **{"from": a, "outcome": "go", "to": b, "active": [b]}))
        seq += 1
    events.append(ev(seq, "terminate", machine=machine, last=labels[-1:], state_outcome="go", outcome="done",
                     active=[]))
    return events


def cut_into_batches(events: list[dict], cuts: list[int]) -> list[list[dict]]:
    """``events`` cut at the given places (any integers: taken modulo one more than their number), in
    order: a batched consumer's property tests compare these batches with the events one by one."""
    places = sorted({c % (len(events) + 1) for c in cuts})
    return [events[a:b] for a, b in zip([0] + places, places + [len(events)])]
