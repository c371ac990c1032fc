"""The problems of tests/problems/fresh, written from the format alone for the kinds the action
generator once could not plan (benchmarks/fresh_problems.py measures them at full size): they
load, and those that need the generator's narrowing pushes, reference ladder and detours round
a post plan. The problems of tests/problems/fresh-large (12-20 parts, issue 32) are measured by the
same script; here they only have to check cleanly."""

from __future__ import annotations

from pathlib import Path

import pytest

import arrange_up
from arrange_up.belief.goals import GoalTest
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.io.yaml_problem import check_problem, load_problem
from arrange_up.model.world import Place, Push

FRESH = Path(__file__).parents[1] / "problems" / "fresh"
FRESH_LARGE = Path(__file__).parents[1] / "problems" / "fresh-large"
EVERY_FRESH = sorted(FRESH.glob("*.yaml")) + sorted(FRESH_LARGE.glob("*.yaml"))


@pytest.mark.parametrize("path", EVERY_FRESH, ids=lambda p: f"{p.parent.name}/{p.stem}")
def test_every_fresh_problem_loads_and_checks_cleanly(path: Path):
    problem, diagnostics = check_problem(path)
    assert not diagnostics, [str(d) for d in diagnostics]  # not even a warning
    assert problem is not None and problem.name == path.stem
    assert load_problem(path).name == path.stem


def test_the_large_fresh_problems_have_12_to_20_parts():
    paths = sorted(FRESH_LARGE.glob("*.yaml"))
    assert len(paths) >= 6
    for path in paths:
        assert 12 <= len(load_problem(path).parts) <= 20, path.stem


def test_a_belief_centred_on_target_but_too_wide_is_narrowed_from_both_sides():
    problem = load_problem(FRESH / "narrow-squeeze.yaml")
    result = arrange_up.plan(problem, particles=10, workers=1)
    assert result.solved, result.reason
    directions = {round(a.pose[2], 3) for a in result.actions if isinstance(a, Push)}
    assert {-1.571, 1.571} <= directions  # pushed right and pushed left
    final = result.beliefs[-1]
    assert GoalTest(problem).satisfied_array(final.poses, final.names())


def test_a_relative_pair_plans_once_its_reference_has_moved_from_the_edge():
    problem = load_problem(FRESH / "relative-pair.yaml")
    result = arrange_up.plan(problem, particles=10, workers=1)
    assert result.solved, result.reason
    assert isinstance(result.actions[0], Push)  # A makes room before B is placed


def test_a_mate_blocked_by_its_references_shadow_alone_is_placed_on_a_ring():
    # Two cubes squared flush in the open (issue 32, gap b): at 50 particles A's shadow covers
    # every place of B's grid, and pushing A about moves the grid with it; B goes one ring out.
    problem = load_problem(FRESH / "open-pair-off.yaml")
    result = arrange_up.plan(problem, particles=50, workers=1, validate=0)
    assert result.solved, result.reason
    first, second = result.actions[:2]
    assert isinstance(first, Place) and first.obj == "A"
    assert isinstance(second, Place) and second.obj == "B"
    assert second.pose[0] - first.pose[0] > 1.7  # a ring out, then pushed in
    final = result.beliefs[-1]
    assert GoalTest(problem).satisfied_array(final.poses, final.names())


def test_a_reference_that_starts_off_the_table_is_put_down_with_room_for_its_mates():
    # Its goal is anywhere; it is placed where the goal arrangement is centred on the table.
    problem = load_problem(FRESH / "reference-off-table.yaml")
    result = arrange_up.plan(problem, particles=5, workers=1, validate=0)
    assert result.solved, result.reason
    first = result.actions[0]
    assert isinstance(first, Place) and first.obj == "R"
    # R (2 x 1) with C on top spans y -0.5..1.55 in R's frame: centred on the 9 x 7 table, R's
    # centre is at (4.5, 2.975), give or take one step of the place grid
    assert abs(first.pose[0] - 4.5) <= 1.0 and abs(first.pose[1] - 2.975) <= 1.0
    final = result.beliefs[-1]
    assert GoalTest(problem).satisfied_array(final.poses, final.names())


def _centres(result, name: str) -> list[tuple[float, float]]:
    """``name``'s belief centre (x, y) after each action of a plan."""
    return [tuple(float(v) for v in b.intervals.get(name).center[:2]) for b in result.beliefs[1:]]


def test_a_post_on_the_straight_line_to_the_goal_is_gone_round():
    # The post stands at the goal's height between the block and its goal: the plan takes the
    # block off that line (beyond the goal's tolerance across) and back.
    problem = load_problem(FRESH / "detour-open-post.yaml")
    result = arrange_up.plan(problem, particles=10, workers=1)
    assert result.solved, result.reason
    goal_y, tolerance = problem.goal.target("A")[1], problem.goal.tolerance[1]
    assert any(abs(y - goal_y) > tolerance + 0.5 for _, y in _centres(result, "A"))
    final = result.beliefs[-1]
    assert GoalTest(problem).satisfied_array(final.poses, final.names())


def test_a_block_whose_shadow_would_catch_a_posts_corner_goes_up_first():
    # post-detour: pushed straight right, some of the block's states catch the post's corner
    # and turn round it; the plan pushes it up clear of the post before taking it right.
    problem = load_problem(FRESH / "post-detour.yaml")
    result = arrange_up.plan(problem, particles=10, workers=1)
    assert result.solved, result.reason
    first = result.actions[0]
    assert isinstance(first, Push) and first.pose[2] == 0.0  # the paddle pushing up (+y)
    # Its shadow (every state, at any angle of its spread) now passes above the post's top.
    after = result.beliefs[1].intervals.get("A")
    shadow = CollisionChecker(problem).shadow_box("A", after.center, after.half)
    assert shadow[1] > 0.6


def test_a_cube_is_pushed_into_the_nook_of_an_ell_squared_in_its_corner():
    # mm-ell-nook: the L starts turned 0.6 rad; squared and pressed into the corner, its nook
    # (2.5 mm to spare round the cube) is open to the cube's place beside it and to the pushes
    # that drive the cube in, the paddle clear of the L's arms.
    problem = load_problem(FRESH / "mm-ell-nook.yaml")
    result = arrange_up.plan(problem, semantics="deterministic")
    assert result.solved, result.reason
    place = next(a for a in result.actions if not isinstance(a, Push))
    goal = problem.goal.target("B")
    assert place.pose[0] > goal[0] and place.pose[1] > goal[1]  # beside the nook, not in it
    final = result.beliefs[-1]
    assert GoalTest(problem).satisfied_array(final.poses, final.names())


def test_a_cube_into_a_bracket_tighter_than_the_place_uncertainty_is_placed_out_and_pushed_in():
    problem = load_problem(FRESH / "bracket-clearance.yaml")
    result = arrange_up.plan(problem, particles=10, workers=1, validate=0)
    assert result.solved, result.reason
    assert isinstance(result.actions[0], Place) and isinstance(result.actions[-1], Push)
    final = result.beliefs[-1]
    assert GoalTest(problem).satisfied_array(final.poses, final.names())
