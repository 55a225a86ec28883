"""A container's states wrapped into rows (fsmscope/server/graph_rows.py): a machine of a few dozen states is
drawn about as wide as a screen, not as a column of boxes no screen shows readable whole."""

from __future__ import annotations

import re

import fsm
from fsm.observation import structure
from fsmscope.server import graph
from fsmscope.server.graph_rows import ranks
from fsmscope.server.testing.mission import mission_machine, sequence_machine


def drawn_size(sm) -> tuple[float, float]:
    """The width and height (points) of the server's drawing of ``sm``, every container open."""
    fsm.set_loggers(*(lambda msg: None,) * 4)
    root = fsm.attach(sm, name="m").structure()
    assert structure.count(root) == 31
    svg = graph.Renderer().render(root, "m").decode()
    w, h = re.search(r'viewBox="0 0 ([\d.]+) ([\d.]+)"', svg).groups()
    return float(w), float(h)


def test_a_31_state_script_is_drawn_wider_than_tall():
    w, h = drawn_size(mission_machine())
    assert 1.0 < w / h < 2.5


def test_a_31_state_script_fits_a_laptops_graph_pane_with_labels_of_9_px():
    w, h = drawn_size(mission_machine())
    assert min(744 / w, 542 / h) * graph.LABEL_PT >= 9.5  # the pane at 1440 x 900, a 9 px floor and a margin


def test_a_sequence_of_30_states_fits_a_laptops_graph_pane_with_labels_of_9_px():
    w, h = drawn_size(sequence_machine(30))
    assert min(744 / w, 542 / h) * graph.LABEL_PT >= 9.5


def test_states_are_ranked_by_their_longest_path_from_the_initial_state_loops_left_out():
    rank = ranks(["A", "B", "C", "D"], ["A"], [("A", "B"), ("B", "C"), ("A", "C"), ("C", "A"), ("C", "D")])
    assert rank == {"A": 0, "B": 1, "C": 2, "D": 3}
