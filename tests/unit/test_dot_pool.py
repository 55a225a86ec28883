"""The kept dot processes (fsmscope/server/dot.py): drawings in order, a process reused, and one that fails or
is too slow replaced without taking the next layout down."""

from __future__ import annotations

import shutil

import pytest

from fsmscope.server.dot import DotError, DotPool

pytestmark = pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz's dot is not installed (make apt)")


def graph(name: str) -> bytes:
    return b'digraph "%s" { a -> b; b -> "%s" }' % (name.encode(), name.encode())


@pytest.fixture
def pool():
    dots = DotPool(2)
    yield dots
    dots.close()


def test_several_graphs_come_back_as_their_drawings_in_order(pool):
    docs = pool.layout([graph("g%d" % i) for i in range(5)], timeout=30)
    assert [doc.count(b"<!-- Title: g%d " % i) for i, doc in enumerate(docs)] == [1] * 5


def test_a_second_layout_uses_the_process_the_first_started(pool):
    pool.layout([graph("first")], timeout=30)
    pid = pool._idle[0].proc.pid
    pool.layout([graph("second")], timeout=30)
    assert [p.proc.pid for p in pool._idle] == [pid]


def test_a_graph_dot_rejects_says_why_and_the_next_layout_works(pool):
    with pytest.raises(DotError, match="syntax error"):
        pool.layout([b"digraph broken { a -> }"], timeout=30)
    assert b"<title>after</title>" in pool.layout([graph("after")], timeout=30)[0]


def test_a_layout_over_its_time_is_stopped_and_the_next_one_works(pool):
    with pytest.raises(DotError, match="longer than"):
        pool.layout([graph("slow")] * 200, timeout=0.001)
    assert b"<title>after</title>" in pool.layout([graph("after")], timeout=30)[0]
    assert pool._running == 1


def test_a_big_drawing_does_not_block_on_a_full_pipe(pool):
    nodes = b"; ".join(b'n%d [label="%s"]' % (i, b"x" * 200) for i in range(400))
    doc, = pool.layout([b"digraph big { " + nodes + b" }"], timeout=60)
    assert len(doc) > 1 << 17 and doc.rstrip().endswith(b"</svg>")
