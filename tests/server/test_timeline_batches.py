"""fsmscope/server/timeline.py: a timeline given a machine's events in batches, however they are cut, is
the timeline given them one by one (a batch of one container's transitions is marked with C's loops:
``TimelineIndex._add_steps``)."""

from event_support import cut_into_batches
from hypothesis import given, settings
from hypothesis import strategies as st

from fsm.observation.schema import build
from fsmscope.server.timeline import TimelineIndex

ROOT, SUB = "/R", "/R/SUB"
actives = st.sampled_from((["A"], ["B"], ["C"], [], ["A", "B"]))


@st.composite
def streams(draw) -> list[dict]:
    """A machine's events: long runs of one container's transitions (whose clock may go back), and
    starts, terminations, errors and the other container's transitions between them."""
    events: list[dict] = []
    t = 100.0
    for run in draw(st.lists(st.sampled_from(("r1", "r2")), min_size=1, max_size=2)):
        for kind, path, active, steps, dt in draw(st.lists(st.tuples(
                st.sampled_from(("transition", "transition", "transition", "start", "terminate", "error")),
                st.sampled_from((ROOT, SUB)), actives, st.integers(1, 30), st.sampled_from((0.5, 0.0, -3.0))),
                min_size=1, max_size=12)):
            for _ in range(steps if kind == "transition" else 1):
                t += dt
                seq = len(events) + 1
                if kind == "transition":
                    to = active[0] if active else None
                    events.append(build.transition(seq, t, run, "m", path, "X", "next", to, active))
                    active = draw(actives)
                elif kind == "start":
                    events.append(build.start(seq, t, run, "m", path, active, active, {}))
                elif kind == "terminate":
                    events.append(build.terminate(seq, t, run, "m", path, active, "done"))
                else:
                    events.append(build.error(seq, t, run, "m", path, "X", "ValueError", "no"))
    return events


def indexed(batches: list[list[dict]]) -> tuple:
    timeline = TimelineIndex()
    for batch in batches:
        timeline.add_all(batch)
    tracks = {path: (list(track.t), list(track.seq), track.label) for path, track in timeline._tracks.items()}
    return tracks, [list(column) for column in timeline._steps], timeline._ticks, timeline._runs, timeline.answer()


@settings(max_examples=300, deadline=None)
@given(streams(), st.lists(st.integers(0, 400), max_size=6))
def test_a_timeline_given_batches_is_the_timeline_given_each_event_in_turn(events, cuts):
    assert indexed(cut_into_batches(events, cuts)) == indexed([[event] for event in events])
