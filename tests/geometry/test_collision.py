"""Tests of ``arrange_up.geometry.collision``: exact footprint tests for world states and the
conservative belief-shadow tests behind action preconditions, on catalogue problems."""

from __future__ import annotations

import math

import numpy as np
import pytest
from catalogue import NAMES, tiny, variant

from arrange_up.geometry.collision import CLEARANCE, CollisionChecker
from arrange_up.geometry.shapes import footprint
from arrange_up.model.world import WorldState

NONE = (0.0, 0.0, 0.0)


def checker_of(name: str) -> CollisionChecker:
    return CollisionChecker(tiny(name))


def state(problem, **poses) -> WorldState:
    return WorldState.from_mapping(problem, poses)


@pytest.fixture(scope="module")
def l_and_square():
    """The L part with a half-inch square that can sit in its notch."""
    return variant(
        "l-part", "objects:\n", "objects:\n  s: {kind: part, shape: {box: [0.5, 0.5]}}\n"
    )


def notch_centre(problem) -> tuple[float, float]:
    """World centre of the L's notch (its missing unit square) at the L's initial pose."""
    x0, y0, _, _ = problem.object("L").shape.extent  # the L's frame corner, centroid-relative
    lx, ly, _ = problem.initial_of("L").pose
    return (lx + x0 + 1.5, ly + y0 + 1.5)


# -- construction ---------------------------------------------------------------------------
@pytest.mark.parametrize("problem", NAMES, indirect=True)
def test_builds_walls_and_obstacles_of_every_catalogue_problem(problem):
    checker = CollisionChecker(problem)
    assert tuple(checker.walls) == problem.table.walls
    assert set(checker.obstacles) == {spec.name for spec in problem.obstacles}
    assert set(checker.shapes) == {spec.name for spec in problem.objects}


# -- world states ---------------------------------------------------------------------------
def test_touching_blocks_do_not_collide_overlapping_ones_do():
    problem = tiny("two-blocks-row")
    checker = CollisionChecker(problem)
    assert not checker.state_collides(state(problem, A=(9.5, 0.5, 0.0), B=(8.5, 0.5, 0.0)))
    assert checker.state_collides(state(problem, A=(9.5, 0.5, 0.0), B=(8.6, 0.5, 0.0)))
    # A corner of a turned block reaches into its neighbour.
    assert checker.state_collides(state(problem, A=(9.5, 0.5, 0.0), B=(8.5, 0.5, math.radians(20))))


def test_a_state_against_a_wall_touches_and_through_it_collides():
    problem = tiny("one-block")
    checker = CollisionChecker(problem)
    assert not checker.state_collides(state(problem, A=(2.5, 1.5, 0.0)))
    assert not checker.state_collides(state(problem, A=(4.5, 0.5, 0.0)))  # flush in the corner
    assert checker.state_collides(state(problem, A=(4.6, 1.5, 0.0)))  # into the right wall
    assert checker.state_collides(state(problem, A=(2.5, 2.6, 0.0)))  # into the top wall


def test_obstacles_collide_and_missing_walls_do_not():
    problem = tiny("obstacle")  # walls on the left and bottom only; a post at (3, 0.5)
    checker = CollisionChecker(problem)
    assert checker.state_collides(state(problem, A=(3.5, 1.0, 0.0)))
    assert not checker.state_collides(state(problem, A=(3.0, 1.5, 0.0)))  # on top of the post
    assert not checker.state_collides(state(problem, A=(6.2, 2.0, 0.0)))  # past the open edge
    assert checker.state_collides(state(problem, A=(-0.2, 2.0, 0.0)))  # into the left wall


def test_a_fixture_on_the_table_is_an_object_like_any_other():
    problem = tiny("block-and-fixture")
    checker = CollisionChecker(problem)
    bar = problem.initial_of("bar").pose
    assert checker.state_collides(state(problem, bar=bar, A=(1.5, 2.0, 0.0)))
    assert not checker.state_collides(state(problem, bar=bar, A=(1.75, 2.0, 0.0)))


def test_exact_footprints_see_the_notch_of_a_non_convex_part(l_and_square):
    checker = CollisionChecker(l_and_square)
    L = l_and_square.initial_of("L").pose
    cx, cy = notch_centre(l_and_square)
    assert len(l_and_square.object("L").shape.parts) == 2
    assert not checker.state_collides(state(l_and_square, L=L, s=(cx, cy, 0.0)))
    assert checker.state_collides(state(l_and_square, L=L, s=(cx - 0.5, cy, 0.0)))


# -- shadows --------------------------------------------------------------------------------
def test_shadow_box_grows_with_the_interval_and_contains_the_nominal_box():
    checker = checker_of("one-block")
    nominal = checker.shadow_box("A", (2.0, 1.5, 0.0), NONE)
    assert nominal == pytest.approx((1.5, 1.0, 2.5, 2.0))
    shadow = checker.shadow_box("A", (2.0, 1.5, 0.0), (0.2, 0.1, math.radians(15)))
    assert shadow[0] < nominal[0] - 0.2 and shadow[1] < nominal[1] - 0.1
    assert shadow[2] > nominal[2] + 0.2 and shadow[3] > nominal[3] + 0.1
    # Lists are accepted like tuples (and share the cache).
    assert checker.shadow_box("A", [2.0, 1.5, 0.0], [0, 0, 0]) == nominal


@pytest.mark.parametrize("name, part", [("l-part", "L"), ("relative-goal", "T")])
def test_shadows_cover_every_pose_of_their_interval(name, part):
    problem = tiny(name)
    checker = CollisionChecker(problem)
    pose, half = (2.5, 2.0, 0.3), (0.2, 0.1, math.radians(20))
    box = checker.shadow_box(part, pose, half)
    hull = checker.shadow_hull(part, pose, half).buffer(1e-9)
    rng = np.random.default_rng(0)
    parts = problem.object(part).shape.parts
    for offset in rng.uniform(-1.0, 1.0, size=(40, 3)):
        sample = tuple(p + o * h for p, o, h in zip(pose, offset, half, strict=True))
        placed = footprint(parts, sample)
        assert hull.contains(placed)
        xmin, ymin, xmax, ymax = placed.bounds
        assert box[0] <= xmin + 1e-9 and box[1] <= ymin + 1e-9
        assert xmax <= box[2] + 1e-9 and ymax <= box[3] + 1e-9


def test_touching_shadows_overlap_and_a_hair_apart_they_do_not():
    checker = checker_of("two-blocks-row")
    a = ("A", (5.0, 2.5, 0.0), NONE)
    assert checker.shadows_overlap(a, ("B", (6.0, 2.5, 0.0), NONE))  # touching counts
    assert not checker.shadows_overlap(a, ("B", (6.0 + 2 * CLEARANCE, 2.5, 0.0), NONE))
    # Uncertainty makes apart blocks overlap: 0.1 in apart, each +-0.2 in.
    far = ("B", (6.1, 2.5, 0.0), NONE)
    assert not checker.shadows_overlap(a, far)
    assert checker.shadows_overlap(("A", (5.0, 2.5, 0.0), (0.2, 0.0, 0.0)), far)
    # Symmetric.
    assert checker.shadows_overlap(far, ("A", (5.0, 2.5, 0.0), (0.2, 0.0, 0.0)))


def test_a_concave_shadow_leaves_its_notch_open_to_what_fits_in_it(l_and_square):
    # The L's shadow is the union of its convex parts' shadows, not one hull that would fill
    # its notch (the unit square missing from it): a half-inch square fits there while the
    # L's pose is known, and its uncertainty closes the notch again.
    checker = CollisionChecker(l_and_square)
    L = l_and_square.initial_of("L").pose
    cx, cy = notch_centre(l_and_square)
    square = ("s", (cx, cy, 0.0), NONE)
    assert not checker.shadows_overlap(("L", L, NONE), square)
    assert not checker.shadows_overlap(square, ("L", L, NONE))
    assert checker.shadows_overlap(("L", L, (0.3, 0.0, 0.0)), square)
    assert checker.shadows_overlap(("L", L, (0.0, 0.0, math.radians(30))), square)
    assert checker.shadows_overlap(("L", L, NONE), ("s", (cx - 0.5, cy, 0.0), NONE))
    # its pieces' boxes split its box; a convex object keeps its one hull and box
    pieces = checker.piece_boxes("L", L, NONE)
    box = checker.shadow_box("L", L, NONE)
    assert len(pieces) == 2
    assert min(b[0] for b in pieces) == pytest.approx(box[0])
    assert max(b[3] for b in pieces) == pytest.approx(box[3])
    assert checker.piece_boxes("s", (cx, cy, 0.0), NONE) == (
        checker.shadow_box("s", (cx, cy, 0.0), NONE),
    )
    assert checker.shadow_hull("s", (cx, cy, 0.0), NONE).geom_type == "Polygon"


def test_shadow_hits_walls_and_obstacles_only_where_they_are():
    one = checker_of("one-block")
    assert one.shadow_hits_fixed("A", (4.5, 0.5, 0.0), NONE)  # flush: touching counts
    assert not one.shadow_hits_fixed("A", (4.3, 0.7, 0.0), NONE)
    assert one.shadow_hits_fixed("A", (4.3, 0.7, 0.0), (0.25, 0.0, 0.0))
    assert not one.shadow_hits_fixed("A", (2.5, 1.5, 0.0), (0.2, 0.2, math.radians(15)))
    post = checker_of("obstacle")
    assert post.shadow_hits_fixed("A", (3.0, 1.6, 0.0), (0.0, 0.2, 0.0))
    assert not post.shadow_hits_fixed("A", (3.0, 1.6, 0.0), NONE)
    assert not post.shadow_hits_fixed("A", (5.7, 2.0, 0.0), (0.2, 0.2, 0.0))  # no right wall
    open_table = checker_of("relative-goal")  # walls: []
    assert not open_table.shadow_hits_fixed("U", (-5.0, -5.0, 0.0), NONE)


def test_shadow_inside_table_checks_the_box_against_the_table():
    checker = checker_of("obstacle")
    assert checker.shadow_inside_table("A", (5.5, 0.5, 0.0), NONE)  # touching edges is fine
    assert not checker.shadow_inside_table("A", (5.5, 0.5, 0.0), (0.01, 0.0, 0.0))
    assert not checker.shadow_inside_table("A", (5.7, 2.0, 0.0), NONE)  # past the open edge
    assert checker.shadow_inside_table("A", (3.0, 2.0, 0.0), (0.2, 0.2, math.radians(15)))


def test_shadow_clear_is_the_place_precondition():
    checker = checker_of("two-blocks-row")
    half = (0.2, 0.2, math.radians(15))
    placed = [("A", (9.088, 0.912, 0.0), half)]
    assert checker.shadow_clear("B", (6.0, 2.5, 0.0), half, placed)
    assert checker.shadow_clear("B", (6.0, 2.5, 0.0), half, [])
    assert not checker.shadow_clear("B", (8.2, 0.912, 0.0), half, placed)  # next to A
    assert not checker.shadow_clear("B", (8.2, 0.912, 0.0), half, iter(placed))
    assert not checker.shadow_clear("B", (0.6, 2.5, 0.0), half, [])  # the left wall


def test_millimetre_problems_are_checked_in_inches():
    inch, mm = checker_of("one-block"), checker_of("millimetres")
    assert mm.walls == inch.walls
    half = tiny("millimetres").uncertainty.place
    assert half == pytest.approx(tiny("one-block").uncertainty.place)
    pose = (4.088, 0.912, 0.0)
    assert mm.shadow_box("A", pose, half) == pytest.approx(inch.shadow_box("A", pose, half))
    assert mm.shadow_hits_fixed("A", pose, half) == inch.shadow_hits_fixed("A", pose, half)
