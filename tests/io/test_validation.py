"""Tests of the semantic checks shared by the readers (``arrange_up.io.validation``)."""

from __future__ import annotations

import dataclasses
import math
import random
from pathlib import Path

import pytest

from arrange_up.geometry import shapes as geometry
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.io.pddl import load_pddl_problem_text, write_pddl_problem
from arrange_up.io.pddl_reader import check_pddl_problem_text
from arrange_up.io.validation import (
    AREA_TOLERANCE,
    MAX_ANGLE,
    MAX_LISTED_OVERLAPS,
    SAMPLE_DRAWS,
    Placed,
    angle_problem,
    check_placement,
    goal_outside,
    goal_overlaps,
    part_overlaps,
    unsampleable,
)
from arrange_up.io.yaml_problem import check_problem_text, load_problem_text
from arrange_up.model.errors import ProblemFormatError
from arrange_up.model.problem import ArrangementProblem, Shape
from arrange_up.model.world import WorldState

BLOCK = Shape((geometry.box_polygon(1.0, 1.0),), box=(1.0, 1.0))

DOMAINS = Path(__file__).parents[2] / "domains"


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


def test_the_angle_limit_is_stated_in_the_unit_the_angle_was_written_in() -> None:
    # The value is in radians; the message quotes it in the file's unit, so must the limit.
    assert "at most 1.67772e+07 rad (" in (angle_problem(1e300) or "")
    assert "at most 1.67772e+07 rad (" in (angle_problem(1e300, "rad") or "")
    in_degrees = angle_problem(math.radians(1e300), "deg") or ""
    assert f"at most {math.degrees(MAX_ANGLE):g} deg (" in in_degrees
    assert "9.61264e+08 deg" in in_degrees and "rad" not in in_degrees


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


# ---------------------------------------------------------------------------------------------
# the same answers at any size
# ---------------------------------------------------------------------------------------------
def _every_pair(placed: list[Placed]) -> list[tuple[tuple[int, float], ...]]:
    """The overlaps of :func:`check_placement` by intersecting every pair of footprints."""
    footprints = [geometry.footprint(p.shape.parts, p.pose) for p in placed]
    found = []
    for j, b in enumerate(footprints):
        pairs = ((i, b.intersection(a).area) for i, a in enumerate(footprints[:j]))
        found.append(tuple((i, area) for i, area in pairs if area > AREA_TOLERANCE))
    return found


def test_placement_finds_the_overlaps_of_every_pair() -> None:
    rng = random.Random(3)
    ell = Shape(tuple(_scene("10, 5", "").objects[1].shape.parts))
    placed = [
        Placed(
            f"O{k}",
            BLOCK if k % 3 else ell,
            (rng.uniform(0, 6), rng.uniform(0, 4), rng.uniform(-3, 3)),
        )
        for k in range(60)
    ]
    expected = _every_pair(placed)
    found = [check.overlaps for check in check_placement(placed, (6.0, 4.0))]
    assert sum(map(len, expected)) > 20  # the scene has many overlaps to find
    assert [[i for i, _ in pairs] for pairs in found] == [[i for i, _ in p] for p in expected]
    for pairs, reference in zip(found, expected, strict=True):
        assert [area for _, area in pairs] == pytest.approx([a for _, a in reference], rel=1e-12)
    blocks = [p for p in placed if p.shape is BLOCK]  # one-part shapes: the very same areas
    assert [c.overlaps for c in check_placement(blocks, None)] == _every_pair(blocks)


def test_placement_stops_after_the_overlaps_asked_for() -> None:
    stacked = [Placed(f"O{k}", BLOCK, (2.0, 2.0, 0.0)) for k in range(30)]
    checks = check_placement(stacked, (5.0, 5.0), max_overlaps=50)
    found = [(j, i) for j, check in enumerate(checks) for i, _ in check.overlaps]
    assert found == [(j, i) for j in range(30) for i in range(j)][:50]


def test_part_overlaps_stop_after_the_overlaps_asked_for() -> None:
    parts = [geometry.box_polygon(1.0, 1.0)] * 20
    everything = part_overlaps(parts)
    assert len(everything) == 190
    assert part_overlaps(parts, max_overlaps=7) == everything[:7]


def _unsampleable_by_the_checker(problem: ArrangementProblem) -> bool:
    """The definition: seeded uniform draws, each tested by ``CollisionChecker``."""
    if not any(any(entry.uncertainty) for entry in problem.initial):
        return False
    checker = CollisionChecker(problem)
    rng = random.Random(0)
    for _ in range(SAMPLE_DRAWS):
        poses = {
            entry.name: tuple(
                entry.pose[k] + rng.uniform(-1.0, 1.0) * entry.uncertainty[k] for k in range(3)
            )
            for entry in problem.initial
        }
        if not checker.state_collides(WorldState.from_mapping(problem, poses)):
            return False
    return True


def _scene(table: str, initial: str, obstacle: str = "") -> ArrangementProblem:
    text = f"""
name: scene
table: {{size: [{table}]}}
objects:
  A: {{kind: part, shape: {{box: [1, 1]}}}}
  B: {{kind: part, shape: {{polygon: [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]}}}}
  C: {{kind: fixture, shape: {{box: [0.5, 2]}}}}
  D: {{kind: fixture, shape: {{box: [0.5, 2]}}}}
  {obstacle}
initial:
{initial}
goal: {{tolerance: [0.2, 0.2], poses: {{A: [0.5, 0.5, 0]}}}}
"""
    with pytest.MonkeyPatch.context() as patch:  # read it even when it is unsampleable
        patch.setattr("arrange_up.io.validation.unsampleable", lambda problem: False)
        return load_problem_text(text)


SCENES = {
    "free": ("10, 5", "  A: {pose: [2, 2, 0], uncertainty: [0.2, 0.2, 10]}"),
    "squeezed between walls": ("1, 3", "  A: {pose: [0.5, 1.5, 0], uncertainty: [0.1, 0, 0]}"),
    "squeezed between parts": (
        "10, 5",
        "  A: {pose: [2, 2, 0], uncertainty: [0.01, 0, 0]}\n"
        "  C: {pose: [1.25, 2, 0]}\n  D: {pose: [2.75, 2, 0]}\n  B: {pose: [6, 2, 0]}",
    ),
    "often free": ("3, 3", "  A: {pose: [0.6, 1.5, 0], uncertainty: [0.3, 0.3, 40]}"),
    "two moving": (
        "4, 2",
        "  A: {pose: [0.5, 0.5, 0], uncertainty: [0.1, 0.1, 5]}\n"
        "  C: {pose: [1.5, 1, 0], uncertainty: [0.4, 0, 0]}",
    ),
    "squeezed between two moving": (
        "1.5, 2",
        "  A: {pose: [0.5, 1, 0], uncertainty: [0.05, 0, 0]}\n"
        "  C: {pose: [1.25, 1, 0], uncertainty: [0.05, 0, 0]}",
    ),
    "beside an obstacle": (
        "4, 2",
        "  A: {pose: [1.5, 0.5, 0], uncertainty: [0.02, 0.02, 0]}",
        "O: {kind: obstacle, shape: {box: [0.5, 0.5]}, pose: [0.75, 0.25, 0]}",
    ),
    "squeezed by an obstacle": (
        "4, 2",
        "  A: {pose: [3.5, 0.5, 0], uncertainty: [0.02, 0, 0]}",
        "O: {kind: obstacle, shape: {box: [0.5, 0.5]}, pose: [2.75, 0.5, 0]}",
    ),
}


@pytest.mark.parametrize("name", sorted(SCENES))
def test_unsampleable_answers_as_the_collision_checker_does(name: str) -> None:
    problem = _scene(*SCENES[name])
    assert unsampleable(problem) is _unsampleable_by_the_checker(problem)


def test_the_scenes_have_both_answers() -> None:
    answers = {name: unsampleable(_scene(*scene)) for name, scene in SCENES.items()}
    assert sum(answers.values()) == 4 and len(answers) == 8


def test_a_stack_of_objects_lists_the_first_overlaps_and_says_there_are_more() -> None:
    names = [f"O{k}" for k in range(16)]  # 120 overlapping pairs, the 101st (O14, O9)
    text = (
        "name: stack\ntable: {size: [5, 5]}\nobjects:\n"
        + "".join(f"  {n}: {{kind: part, shape: {{box: [1, 1]}}}}\n" for n in names)
        + "initial:\n"
        + "".join(f"  {n}: {{pose: [2, 2, 0]}}\n" for n in names)
        + "goal: {tolerance: [0.2, 0.2], poses: {O0: [2, 2, 0]}}\n"
    )
    _, diagnostics = check_problem_text(text, "stack.yaml")
    errors = [d for d in diagnostics if d.severity == "error"]
    assert len(errors) == MAX_LISTED_OVERLAPS + 1
    assert all(" overlaps O" in d.message for d in errors[:-1])
    last = errors[-1]
    assert last.path == "initial.O14.pose" and last.line == 35
    assert last.message.startswith(
        f"O14 and more objects overlap at their nominal poses: only the first "
        f"{MAX_LISTED_OVERLAPS} overlapping pairs are listed"
    )


def test_a_shape_of_stacked_parts_lists_the_first_overlaps_and_says_there_are_more() -> None:
    square = "[[0, 0], [1, 0], [1, 1], [0, 1]]"
    text = (
        "name: parts\ntable: {size: [5, 5]}\nobjects:\n  A:\n    kind: part\n    shape:\n"
        f"      convex_parts: [{', '.join([square] * 16)}]\n"
        "goal: {tolerance: [0.2, 0.2], poses: {A: [2, 2, 0]}}\n"
    )
    _, diagnostics = check_problem_text(text, "parts.yaml")
    errors = [d for d in diagnostics if d.severity == "error"]
    assert len(errors) == MAX_LISTED_OVERLAPS + 1
    assert errors[-1].message.startswith("part [14] and more parts overlap: only the first")


def test_parts_that_overlap_at_their_goal_poses_are_a_warning_in_both_readers() -> None:
    # The Z of the TZ mating moved 0.3 in left (its goal x in the T's frame 1.2 instead of
    # 1.5): its lower column overlaps the T's stem by 0.3 x 2 in, its upper one the end of the
    # T's bar by 0.3 x 1 in.
    text = (DOMAINS / "tz-mating.yaml").read_text()
    overlapping = text.replace("Z: [1.5, -0.4, 90]", "Z: [1.2, -0.4, 90]")
    problem, diagnostics = check_problem_text(overlapping, "tz.yaml")
    assert problem is not None  # a warning: a pose within the tolerance may separate them
    assert goal_overlaps(problem) == [("T", "Z", pytest.approx(0.9))]
    (warning,) = [str(d) for d in diagnostics]
    assert "tz.yaml:" in warning and "goal.relative.poses.Z" in warning
    assert "at their goal poses T and Z overlap by 0.9 square in" in warning
    # The shipped goal only touches; the PDDL reader says the same of its twin.
    assert goal_overlaps(check_problem_text(text, "tz.yaml")[0]) == []
    pddl = (DOMAINS / "tz-mating.pddl").read_text()
    moved = pddl.replace(
        "(>= (rel-x Z T) 1.3) (<= (rel-x Z T) 1.7)", "(>= (rel-x Z T) 1.0) (<= (rel-x Z T) 1.4)"
    )
    problem, diagnostics = check_pddl_problem_text(moved, "tz.pddl")
    assert problem is not None
    (warning,) = [str(d) for d in diagnostics]
    assert ": warning: " in warning and "T and Z overlap by 0.9 square in" in warning
    _, clean = check_pddl_problem_text(pddl, "tz.pddl")
    assert clean == []
