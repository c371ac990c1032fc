"""Goal parts that cannot fit on the table at any pose their goal allows are proven unsolvable
before searching (arrange_up.planning.fitting), with a reason naming the part and why."""

from __future__ import annotations

import math

import numpy as np

from arrange_up.io.yaml_problem import load_problem_text
from arrange_up.planning.fitting import _ruled_out, too_large, unfit_parts
from arrange_up.planning.planner import plan
from arrange_up.search import SearchStatus

#: The probe's problem: a 12 x 1 in bar on a 10 x 5 in table fits it at no angle at all.
TOO_BIG = """
name: too-big
table: {size: [10, 5], walls: [left, right, bottom, top]}
objects:
  A: {kind: part, shape: {box: [12, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
goal:
  tolerance: [0.2, 0.2, 15]
  poses: {A: [5, 0.5, 0]}
uncertainty:
  place: [0.2, 0.2, 15]
  push: [0.05, 0.05, 3]
  friction: [0.25, 0.55]
"""

#: A 5 x 0.5 in bar on a 4 x 4 in table: it fits only turned by 45 degrees or so (5.5/sqrt(2)
#: = 3.9 in), never within 10 degrees of 0 (at 10 degrees it spans 5.01 in along x).
THIN = """
name: thin
table: {size: [4, 4]}
objects:
  A: {kind: part, shape: {box: [5, 0.5]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
goal:
  tolerance: [0.2, 0.2, 10]
  poses: {A: [2, 2, 0]}
"""

#: A 4 x 1 in bar whose goal centre, 1 +- 0.2 in from the left edge, puts its left end
#: through the left wall at every angle within 15 degrees of 0.
AGAINST_WALL = """
name: against-wall
table: {size: [10, 5], walls: [left, right, bottom, top]}
objects:
  A: {kind: part, shape: {box: [4, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
goal:
  tolerance: [0.2, 0.2, 15]
  poses: {A: [1, 2.5, 0]}
"""


def _load(text: str):
    return load_problem_text(text, "test")


def test_a_part_longer_than_the_table_at_every_angle_is_proven_unsolvable():
    problem = _load(TOO_BIG)
    assert too_large(problem) == ("A",)
    result = plan(problem, semantics="deterministic")
    assert result.status is SearchStatus.UNSOLVABLE and result.actions is None
    assert result.stats["expanded"] == 0
    assert (
        result.reason == "part A (12 x 1 in) fits the 10 x 5 in table at no angle: no plan exists"
    )


def test_the_goal_angle_decides_whether_a_thin_part_fits_a_walled_table():
    result = plan(_load(THIN), semantics="deterministic")
    assert result.status is SearchStatus.UNSOLVABLE and result.stats["expanded"] == 0
    assert result.reason == (
        "part A (5 x 0.5 in) fits the 4 x 4 in table at no angle its goal allows (0 ± 10°): "
        "no plan exists"
    )
    # Turned by 45 degrees it fits: a goal allowing that angle is left to the search.
    assert too_large(_load(THIN.replace("[0.2, 0.2, 10]", "[0.2, 0.2, 45]"))) == ()
    assert too_large(_load(THIN.replace("[0.2, 0.2, 10]", "[0.2, 0.2]"))) == ()
    assert too_large(_load(THIN.replace("[2, 2, 0]", "[2, 2, 45]"))) == ()
    # Without walls the part may hang over an edge: only fitting at no angle at all proves.
    open_table = THIN.replace("table: {size: [4, 4]}", "table: {size: [4, 4], walls: []}")
    assert too_large(_load(open_table)) == ()


def test_a_goal_position_through_a_wall_is_proven_only_where_the_table_is_walled():
    problem = _load(AGAINST_WALL)
    (unfit,) = unfit_parts(problem)
    assert unfit.why == (
        "part A (4 x 1 in) fits the 10 x 5 in table at no pose its goal allows "
        "(x 1 ± 0.2, y 2.5 ± 0.2 in, angle 0 ± 15°)"
    )
    # An open left edge lets the bar hang over it; further right the bar fits.
    open_left = AGAINST_WALL.replace("[left, right, bottom, top]", "[right, bottom, top]")
    assert too_large(_load(open_left)) == ()
    assert too_large(_load(AGAINST_WALL.replace("[1, 2.5, 0]", "[2.1, 2.5, 0]"))) == ()


def test_the_reason_is_in_the_problems_units():
    text = (
        TOO_BIG.replace("name: too-big", "name: too-big\nunits: {length: cm, angle: rad}")
        .replace("[12, 1]", "[30, 2]")
        .replace("[10, 5]", "[25, 12]")
        .replace("tolerance: [0.2, 0.2, 15]", "tolerance: [0.5, 0.5, 0.25]")
        .replace("[5, 0.5, 0]", "[12.5, 1, 0]")
        .replace("place: [0.2, 0.2, 15]", "place: [0.5, 0.5, 0.25]")
        .replace("push: [0.05, 0.05, 3]", "push: [0.1, 0.1, 0.05]")
    )
    (unfit,) = unfit_parts(_load(text))
    assert unfit.why == "part A (30 x 2 cm) fits the 25 x 12 cm table at no angle"
    turned = text.replace("[30, 2]", "[26, 1]")  # fits only turned, as THIN
    (unfit,) = unfit_parts(_load(turned))
    assert unfit.why == (
        "part A (26 x 1 cm) fits the 25 x 12 cm table at no angle its goal allows (0 ± 0.25 rad)"
    )


def test_a_relative_goals_parts_and_reference_may_turn_and_so_fit_if_any_angle_fits():
    text = """
name: relative
table: {size: [10, 5]}
objects:
  R: {kind: part, shape: {box: [1, 1]}}
  A: {kind: part, shape: {box: %s}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
goal:
  tolerance: [0.2, 0.2, 5]
  relative: {reference: %s, poses: {%s: [0, 3, 0]}}
"""
    # A mate of the reference is turned with it: fitting at some angle is enough.
    assert too_large(_load(text % ("[10.2, 0.5]", "R", "A"))) == ()
    assert too_large(_load(text % ("[12, 1]", "R", "A"))) == ("A",)
    # The reference must be on the table too.
    assert too_large(_load(text % ("[12, 1]", "A", "R"))) == ("A",)


def test_a_ruled_out_interval_has_no_angle_that_fits_by_brute_force():
    """Soundness of the cell bounds on random polygons, tables and goal boxes: whatever is
    ruled out fits at none of 20001 angles across the interval."""
    rng = np.random.default_rng(7)
    proven = 0
    for _ in range(300):
        points = rng.normal(size=(int(rng.integers(3, 7)), 2)) * rng.uniform(0.5, 4.0)
        points -= points.mean(axis=0)
        width, depth = rng.uniform(1.0, 8.0, 2)
        centre, tol = rng.uniform(0.0, 2 * math.pi), rng.uniform(0.0, 0.6)
        boxes = None
        if rng.random() < 0.5:
            gx, gy, tx, ty = rng.uniform(0, width), rng.uniform(0, depth), *rng.uniform(0, 1, 2)
            boxes = ((gx - tx, gx + tx), (gy - ty, gy + ty))
        if not _ruled_out(points, [(centre - tol, centre + tol)], (width, depth), boxes):
            continue
        proven += 1
        angles = np.linspace(centre - tol, centre + tol, 20001)[:, None]
        fits = np.ones(len(angles), dtype=bool)
        for axis, size in enumerate((width, depth)):
            c, s = np.cos(angles), np.sin(angles)
            p = (
                points[:, 0] * c - points[:, 1] * s
                if axis == 0
                else points[:, 0] * s + points[:, 1] * c
            )
            lo, hi = p.min(axis=1), p.max(axis=1)
            if boxes is None:
                fits &= hi - lo <= size
            else:
                fits &= np.maximum(-lo, boxes[axis][0]) <= np.minimum(size - hi, boxes[axis][1])
        assert not fits.any()
    assert proven > 50
