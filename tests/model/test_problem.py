"""Tests of the problem data (``arrange_up.model.problem``): shapes, keyed access and the
content hash."""

from __future__ import annotations

import dataclasses

import pytest

from arrange_up.model.problem import (
    ArrangementProblem,
    Goal,
    InitialObject,
    ObjectKind,
    ObjectSpec,
    Shape,
    Table,
    problem_hash,
)
from arrange_up.model.units import Units


def box(width: float, height: float) -> Shape:
    w, h = width / 2, height / 2
    return Shape((((-w, -h), (w, -h), (w, h), (-w, h)),), box=(width, height))


PADDLE = box(2.5, 0.15)
BLOCK = box(1.0, 1.0)


def make_problem(**changes: object) -> ArrangementProblem:
    problem = ArrangementProblem(
        name="p",
        table=Table((10.0, 5.0)),
        objects=(
            ObjectSpec("A", ObjectKind.PART, BLOCK),
            ObjectSpec("paddle", ObjectKind.MANIPULATOR, PADDLE),
            ObjectSpec("post", ObjectKind.OBSTACLE, BLOCK, (8.0, 4.0, 0.0)),
        ),
        initial=(InitialObject("A", (1.0, 1.0, 0.0), (0.1, 0.1, 0.0)),),
        goal=Goal((("A", (5.0, 2.0, 0.0)),), (0.2, 0.2, None)),
    )
    return dataclasses.replace(problem, **changes)


def test_shape_extent_area_and_radius_of_a_box() -> None:
    assert PADDLE.extent == pytest.approx((-1.25, -0.075, 1.25, 0.075))
    assert PADDLE.area == pytest.approx(2.5 * 0.15)
    assert BLOCK.radius == pytest.approx(2**0.5 / 2)
    assert len(list(BLOCK.vertices())) == 4


def test_a_manipulator_pushes_perpendicular_to_its_long_side() -> None:
    wide = ObjectSpec("m", ObjectKind.MANIPULATOR, PADDLE)
    tall = ObjectSpec("m", ObjectKind.MANIPULATOR, box(0.15, 2.5))
    assert wide.push_direction == (0.0, 1.0)
    assert tall.push_direction == (-1.0, 0.0)


def test_keyed_access_by_name_and_kind() -> None:
    problem = make_problem()
    assert problem.object("post").pose == (8.0, 4.0, 0.0)
    assert [s.name for s in problem.parts] == ["A"]
    assert [s.name for s in problem.manipulators] == ["paddle"]
    assert [s.name for s in problem.obstacles] == ["post"]
    assert problem.fixtures == ()
    assert problem.initial_of("A").uncertainty == (0.1, 0.1, 0.0)
    assert problem.initial_of("paddle") is None
    with pytest.raises(KeyError, match="declares no object 'B'"):
        problem.object("B")
    goal = problem.goal
    assert goal.target("A") == (5.0, 2.0, 0.0) and goal.parts == ("A",)
    assert not goal.is_relative
    with pytest.raises(KeyError):
        goal.target("B")


def test_problem_hash_covers_the_content_only() -> None:
    problem = make_problem()
    digest = problem_hash(problem)
    assert digest.startswith("sha256:") and len(digest) == len("sha256:") + 64
    same = make_problem(description="other words", units=Units("cm", "rad"), source="x.pddl")
    assert problem_hash(same) == digest
    # numbers are rounded to 9 significant digits: a float's last bits do not matter
    nudged = make_problem(initial=(InitialObject("A", (1.0 + 1e-13, 1.0, 0.0), (0.1, 0.1, 0.0)),))
    assert problem_hash(nudged) == digest
    moved = make_problem(initial=(InitialObject("A", (1.5, 1.0, 0.0), (0.1, 0.1, 0.0)),))
    assert problem_hash(moved) != digest
    assert problem_hash(make_problem(table=Table((10.0, 5.0), ()))) != digest
