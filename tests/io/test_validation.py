"""Tests of the semantic checks shared by the readers (``arrange_up.io.validation``)."""

from __future__ import annotations

import dataclasses

import pytest

from arrange_up.geometry import shapes as geometry
from arrange_up.io.pddl import load_pddl_problem_text, write_pddl_problem
from arrange_up.io.validation import (
    AREA_TOLERANCE,
    MAX_ANGLE,
    SAMPLE_DRAWS,
    Placed,
    angle_problem,
    check_placement,
    goal_outside,
    part_overlaps,
    unsampleable,
)
from arrange_up.io.yaml_problem import check_problem_text, load_problem_text
from arrange_up.model.errors import ProblemFormatError
from arrange_up.model.problem import Shape

BLOCK = Shape((geometry.box_polygon(1.0, 1.0),), box=(1.0, 1.0))


def test_overlap_is_reported_by_the_later_object_with_its_area() -> None:
    placed = [
        Placed("A", BLOCK, (1.0, 1.0, 0.0)),
        Placed("B", BLOCK, (3.0, 1.0, 0.0)),
        Placed("C", BLOCK, (1.5, 1.5, 0.0)),
    ]
    a, b, c = check_placement(placed, (10.0, 5.0))
    assert a.ok and b.ok
    assert c.outside is None
    ((index, area),) = c.overlaps
    assert index == 0 and area == pytest.approx(0.25)


def test_touching_is_not_overlapping_and_the_table_edge_is_inside() -> None:
    placed = [Placed("A", BLOCK, (0.5, 0.5, 0.0)), Placed("B", BLOCK, (1.5, 0.5, 0.0))]
    assert all(check.ok for check in check_placement(placed, (2.0, 1.0)))
    assert AREA_TOLERANCE > 0


def test_outside_gives_the_footprint_bounds_and_no_table_skips_the_check() -> None:
    placed = [Placed("A", BLOCK, (9.8, 1.0, 0.0))]
    (check,) = check_placement(placed, (10.0, 5.0))
    assert check.outside == pytest.approx((9.3, 0.5, 10.3, 1.5))
    (unchecked,) = check_placement(placed, None)
    assert unchecked.ok


VALID = """\
name: placed
table: {size: [10, 5]}
objects:
  A: {kind: part, shape: {box: [1, 1]}}
  B: {kind: part, shape: {box: [1, 1]}}
  C: {kind: part, shape: {box: [1, 1]}}
initial:
  A: {pose: [1, 1, 0]}
  B: {pose: [3, 1, 0]}
  C: {pose: [5, 1, 0]}
goal:
  tolerance: [0.2, 0.2]
  poses: {A: [5, 3, 0]}
"""


def test_both_readers_report_the_same_placement_problems() -> None:
    """B overlapping A and C off the table: the YAML and the PDDL reader find the same two
    problems, with the same partner, area and extent."""
    pddl = write_pddl_problem(load_problem_text(VALID))
    pddl = pddl.replace("(= (x B) 3) (= (y B) 1)", "(= (x B) 1.5) (= (y B) 1.5)")
    pddl = pddl.replace("(= (x C) 5)", "(= (x C) 9.8)")
    yaml = VALID.replace("B: {pose: [3, 1, 0]}", "B: {pose: [1.5, 1.5, 0]}")
    yaml = yaml.replace("C: {pose: [5, 1, 0]}", "C: {pose: [9.8, 1, 0]}")

    problem, diagnostics = check_problem_text(yaml, "placed.yaml")
    assert problem is None
    from_yaml = [d for d in diagnostics if d.is_error]
    with pytest.raises(ProblemFormatError) as caught:
        load_pddl_problem_text(pddl, "placed.pddl")
    from_pddl = list(caught.value.errors)

    for errors in (from_yaml, from_pddl):
        assert len(errors) == 2, "\n".join(str(e) for e in errors)
        overlap, outside = sorted(errors, key=lambda d: d.message)
        assert overlap.message.startswith("B overlaps A ")
        assert "(overlap area 0.25 in²)" in overlap.message
        assert outside.message.startswith("C lies outside the table")
        assert "x 9.3..10.3, y 0.5..1.5" in outside.message
        assert overlap.line is not None and outside.line is not None


def test_part_overlaps_reports_each_overlapping_pair_once() -> None:
    left = ((0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0))
    touching = ((1.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0))
    across = ((0.5, 0.0), (1.5, 0.0), (1.5, 0.5), (0.5, 0.5))
    ((i, j, area), (i2, j2, area2)) = part_overlaps([left, touching, across])
    assert (i, j, i2, j2) == (0, 2, 1, 2)
    assert area == pytest.approx(0.25) and area2 == pytest.approx(0.25)
    assert part_overlaps([left, touching]) == []


def test_angles_beyond_the_resolution_of_a_double_are_refused() -> None:
    assert angle_problem(0.0) is None and angle_problem(-MAX_ANGLE) is None
    for bad in (MAX_ANGLE * 2, 1e300, float("nan"), float("inf")):
        assert "expected an angle" in (angle_problem(bad) or "")


def test_a_goal_off_the_table_is_unreachable_one_at_its_edge_sticks_out() -> None:
    table, tolerance = (10.0, 5.0), (0.2, 0.2)
    assert goal_outside(BLOCK, (5.0, 2.0, 0.0), tolerance, table) is None
    assert goal_outside(BLOCK, (9.7, 2.0, 0.0), tolerance, table)[0] == "sticks out"
    # the centroid 0.1 in beyond the edge, within the tolerance: still reachable in principle
    assert goal_outside(BLOCK, (10.1, 2.0, 0.0), tolerance, table)[0] == "sticks out"
    verdict, bounds = goal_outside(BLOCK, (10.3, 2.0, 0.0), tolerance, table)
    assert verdict == "unreachable" and bounds == pytest.approx((9.8, 1.5, 10.8, 2.5))


ROW = """\
name: row
table: {size: [10, 5], walls: [left]}
objects:
  A: {kind: part, shape: {box: [1, 1]}}
  B: {kind: part, shape: {box: [1, 1]}}
initial:
  A: {pose: [0.5, 2, 0], uncertainty: [0, 0, 0]}
  B: {pose: [1.5, 2, 0]}
goal:
  tolerance: [0.2, 0.2]
  poses: {A: [5, 2, 0]}
"""


def test_a_belief_is_unsampleable_only_when_no_draw_is_free() -> None:
    problem = load_problem_text(ROW)
    assert not unsampleable(problem)  # nothing uncertain: nothing to draw

    def moving(half: float):
        a, b = problem.initial
        return dataclasses.replace(
            problem, initial=(dataclasses.replace(a, uncertainty=(half, 0.0, 0.0)), b)
        )

    # A pressed between the wall and B: every draw that moves it overlaps one of them
    assert unsampleable(moving(0.3))
    # B away from A: every draw that moves A to the right is free
    moved = moving(0.3)
    b = moved.initial[1]
    spaced = dataclasses.replace(
        moved, initial=(moved.initial[0], dataclasses.replace(b, pose=(3.0, 2.0, 0.0)))
    )
    assert not unsampleable(spaced)


def test_the_readers_refuse_an_unsampleable_belief_where_it_is_written() -> None:
    text = ROW.replace("uncertainty: [0, 0, 0]", "uncertainty: [0.3, 0, 0]")
    problem, diagnostics = check_problem_text(text, "row.yaml")
    assert problem is None
    (error,) = diagnostics
    assert str(error).startswith("row.yaml:7:3: error: initial: no collision-free initial state")
    assert f"in {SAMPLE_DRAWS} draws" in error.message
