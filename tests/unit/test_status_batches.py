"""fsm.observation.status: a Status folded from a batch of events, however the events are cut into
batches, is the Status folded from them one by one (a batch's transitions of one container, one
after the other, are folded as one: only the last settles the container)."""

from event_support import cut_into_batches
from hypothesis import given, settings
from hypothesis import strategies as st

from fsm.observation.schema import build
from fsm.observation.status import Status

ROOT, SUB = "/R", "/R/SUB"
STATES = ("A", "B", "C")
values = st.dictionaries(st.sampled_from(("count", "pose", "name")), st.integers(0, 3), max_size=2)


@st.composite
def streams(draw) -> list[dict]:
    """Two runs' worth of a machine's events: starts, runs of transitions (with and without the writes
    they carry, up to 21 of one container in a row) in the root and a child container, userdata events
    between them, terminations."""
    events: list[dict] = []

    def add(make, path, *args, **optional):
        events.append(make(len(events) + 1, float(len(events)), run, "m", path, *args, **optional))

    for run in draw(st.lists(st.sampled_from(("r1", "r2")), min_size=1, max_size=2)):
        add(build.start, ROOT, ["A"], ["A"], draw(values))
        for kind, path, frm, to, changes, steps in draw(st.lists(st.tuples(
                st.sampled_from(("transition", "transition", "transition", "userdata", "start", "terminate")),
                st.sampled_from((ROOT, SUB)), st.sampled_from(STATES), st.sampled_from(STATES), values,
                st.lists(values, max_size=20)), min_size=4, max_size=40)):
            if kind == "transition":  # and a run of the container's transitions after it, each with its writes
                for written in [changes] + steps:
                    add(build.transition, path, frm, "next", to, [to], **({"changes": written} if written else {}))
            elif kind == "userdata" and changes:
                add(build.userdata, path, changes)
            elif kind == "start":
                add(build.start, path, [to], [to], changes)
            elif kind == "terminate":
                add(build.terminate, path, [frm], "done", state_outcome="next",
                    **({"changes": changes} if changes else {}))
        add(build.terminate, ROOT, ["A"], "done")
    return events


def folded(batches: list[list[dict]]) -> dict:
    status = Status("m")
    for batch in batches:
        status.apply_all(batch)
    return status.to_dict()


@settings(max_examples=300, deadline=None)
@given(streams(), st.lists(st.integers(0, 200), max_size=6))
def test_a_status_folded_in_batches_is_the_status_folded_event_by_event(events, cuts):
    assert folded(cut_into_batches(events, cuts)) == folded([[event] for event in events])
