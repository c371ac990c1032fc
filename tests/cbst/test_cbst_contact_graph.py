"""CBST structure: the canonical frame and the contact graph (no learned model involved)."""

from __future__ import annotations

import math

import pytest

from arrange_up.cbst.contact_graph import (
    ROBOT,
    WALL,
    Node,
    Paddle,
    analyse_push,
    make_contact_graph,
    maximal_paths,
)
from arrange_up.cbst.frame import DIRECTION_NAMES, CanonicalFrame
from arrange_up.geometry.shapes import shadow_box

SQUARE = (((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)),)
PADDLE = (((-1.25, -0.075), (1.25, -0.075), (1.25, 0.075), (-1.25, 0.075)),)
EAST = -0.5 * math.pi
WALL_U = 10.0


def block(name: str, u: float, v: float, half=(0.05, 0.05, 0.05), **kw) -> Node:
    return Node(name, (u, v, 0.0), half, shadow_box(SQUARE, (u, v, 0.0), half), **kw)


def paddle(u: float, v: float, travel: float = 20.0, half=(0.05, 0.05, 0.05)) -> Paddle:
    return Paddle((u, v, EAST), half, shadow_box(PADDLE, (u, v, EAST), half), 2.5, 0.15, travel)


def analyse(p, nodes, wall=WALL_U, **kw):
    return analyse_push(p, nodes, wall=wall, block_size=1.0, **kw)


# -- frame -------------------------------------------------------------------------------------
@pytest.mark.parametrize("direction", DIRECTION_NAMES)
def test_frame_round_trips_and_points_the_push_to_plus_u(direction):
    frame = CanonicalFrame(direction)
    ux, uy = frame.vector
    assert frame.point_to(ux, uy) == pytest.approx((1.0, 0.0))
    pose = (1.5, -2.25, 0.3)
    assert frame.pose_from(frame.pose_to(pose)) == pytest.approx(pose)
    assert frame.half_from(frame.half_to((0.1, 0.2, 0.3))) == (0.1, 0.2, 0.3)
    box = (1.0, 2.0, 4.0, 3.0)
    u0, v0, u1, v1 = frame.box_to(box)
    assert (u1 - u0, v1 - v0) == pytest.approx((3.0, 1.0) if not frame.swaps else (1.0, 3.0))
    # The wall ahead is at the table box's umax.
    table = frame.table_box((10.0, 5.0))
    wall_point = {"right": (10, 2), "left": (0, 2), "top": (5, 5), "bottom": (5, 0)}
    assert frame.point_to(*wall_point[frame.wall_ahead])[0] == pytest.approx(table[2])
    assert CanonicalFrame.of_vector(ux, uy) == frame


def test_frame_rejects_diagonal_pushes():
    assert CanonicalFrame.of_vector(math.sqrt(0.5), math.sqrt(0.5)) is None
    with pytest.raises(ValueError):
        CanonicalFrame("+z")


# -- graphs ------------------------------------------------------------------------------------
def test_single_train_is_one_maximal_path_with_certain_contacts():
    nodes = [block("A", 9.45, 2.0), block("B", 8.0, 2.1)]
    graph = make_contact_graph(paddle(6.8, 2.0), nodes, wall=WALL_U, block_size=1.0)
    assert maximal_paths(graph) == [(ROBOT, "B", "A", WALL)]
    assert graph.certain(ROBOT, "B") and graph.certain("B", "A")
    # Every node has an edge to the wall (thesis Figure 3-3).
    assert all(graph.has_edge(n, WALL) for n in (ROBOT, "A", "B"))
    s = analyse(paddle(6.8, 2.0), nodes)
    assert s.kind == "predict" and s.length == 2
    assert [(m.name, m.depth, m.prevs, m.nexts) for m in s.members] == [
        ("B", 2, (ROBOT,), ("A",)),
        ("A", 1, ("B",), (WALL,)),
    ]


def test_two_rows_of_equal_length_are_both_compressed():
    nodes = [
        block("A", 9.45, 0.5),
        block("B", 8.4, 0.5),
        block("C", 9.45, 1.5),
        block("D", 8.4, 1.5),
    ]
    s = analyse(paddle(7.2, 1.0), nodes)
    assert s.kind == "predict" and s.length == 2
    depths = {m.name: m.depth for m in s.members}
    assert depths == {"A": 1, "B": 2, "C": 1, "D": 2}
    # Flush rows graze each other (possible contacts) but each object has its own certain
    # neighbours.
    members = {m.name: m for m in s.members}
    assert members["A"].prevs == ("B",) and members["C"].prevs == ("D",)


def test_uneven_paths_shorter_one_out_of_reach_is_left_alone():
    # Row 1: a 2-block train; row 2: one block far from the paddle's closest approach.
    nodes = [block("A", 9.45, 0.6), block("B", 8.4, 0.6), block("E", 9.4, 1.9)]
    s = analyse(paddle(7.2, 1.25), nodes)
    assert s.kind == "predict"
    assert {m.name for m in s.members} == {"A", "B"}
    assert "E" in s.untouched


def test_uneven_paths_shorter_one_in_reach_is_unpredictable():
    nodes = [block("A", 9.45, 0.6), block("B", 8.4, 0.6), block("E", 8.2, 1.9)]
    s = analyse(paddle(6.9, 1.25), nodes)
    assert s.kind == "none" and "shorter" in s.reason


def test_no_wall_ahead_is_unpredictable():
    s = analyse(paddle(6.8, 2.0), [block("A", 9.0, 2.0)], wall=None)
    assert s.kind == "none" and "wall" in s.reason


def test_non_block_and_obstacle_are_unpredictable():
    s = analyse(paddle(6.8, 2.0), [block("A", 9.0, 2.0, block=False)])
    assert s.kind == "none" and "not a block" in s.reason
    s = analyse(paddle(6.8, 2.0), [block("A", 8.0, 2.0)], obstacles=[(9.0, 1.8, 9.5, 2.2)])
    assert s.kind == "none" and "obstacle" in s.reason


def test_paddle_touching_nothing_leaves_the_belief_unchanged():
    s = analyse(paddle(6.8, 2.0, travel=0.5), [block("A", 9.0, 2.0)])
    assert s.kind == "unchanged"
    s = analyse(paddle(6.8, 4.5), [block("A", 9.0, 1.0)])  # beside the paddle's sweep
    assert s.kind == "unchanged"


def test_push_that_stops_short_of_compression_is_unpredictable():
    # Front at 6.875; compressed train front at 9.0; a travel of 1.5 stops at 8.375.
    s = analyse(paddle(6.8, 2.0, travel=1.5), [block("A", 8.0, 2.0)])
    assert s.kind == "none" and "short" in s.reason


def test_grazing_paddle_end_is_uncertain_and_unpredictable():
    # The block overlaps the paddle's span by less than MIN_OVERLAP in some states.
    s = analyse(paddle(6.8, 2.0), [block("A", 9.0, 3.7, half=(0.05, 0.2, 0.05))])
    assert s.kind == "none" and "may or may not be pushed" in s.reason


def test_offset_next_block_may_be_slipped_past():
    # B is offset so far across the push that the contact with A is not certain.
    s = analyse(
        paddle(6.8, 2.0),
        [
            block("A", 9.45, 2.8, half=(0.05, 0.1, 0.05)),
            block("B", 8.0, 2.0, half=(0.05, 0.1, 0.05)),
        ],
    )
    assert s.kind == "none" and "slide past" in s.reason


def test_side_by_side_blocks_get_no_edge():
    # Same position along the push, a row apart: a push slides them along each other.
    nodes = [block("A", 9.45, 0.5), block("C", 9.45, 1.5)]
    graph = make_contact_graph(paddle(8.2, 1.0), nodes, wall=WALL_U, block_size=1.0)
    assert not graph.has_edge("A", "C") and not graph.has_edge("C", "A")


def test_flush_object_grazed_by_a_neighbouring_row_is_kept():
    # Row 1: B pushed toward A at the wall; row 2: C already flush at the wall, within the
    # paddle's span but out of its reach; B's corner may graze C.
    a = block("A", 9.49, 0.55, half=(0.01, 0.05, 0.04))
    b = block("B", 8.1, 0.5, half=(0.29, 0.012, 0.05))
    c = block("C", 9.49, 1.49, half=(0.011, 0.091, 0.042))
    s = analyse(paddle(7.07, 1.32), [a, b, c])
    assert s.kind == "predict"
    members = {m.name: m for m in s.members}
    assert members["C"].grazed and members["C"].grazers == ("B",) and members["C"].depth == 1
    assert 0.0 < members["C"].graze < 0.2
    assert not members["A"].grazed and members["A"].prevs == ("B",)
    # The same C not yet flush could be pushed, or not: no prediction.
    c_back = block("C", 9.2, 1.49, half=(0.011, 0.091, 0.042))
    s = analyse(paddle(7.07, 1.32), [a, b, c_back])
    assert s.kind == "none" and "may or may not be pushed" in s.reason
