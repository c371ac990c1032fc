"""Tests of ``arrange_up.planning.heuristics``: every heuristic of HEURISTICS at and away from a
goal, the per-dimension count, and the part-ordering filter (rows, walled-in parts)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from catalogue import tiny, with_planning

import arrange_up
from arrange_up.belief.compiled import compile_problem
from arrange_up.belief.goals import GoalTest
from arrange_up.belief.states import AngleFrame, ParticleBelief
from arrange_up.model.world import WorldState
from arrange_up.planning.actions import ActionGenerator
from arrange_up.planning.heuristics import HEURISTICS, make_heuristic, per_dimension_count

PARTICLES = 5


def heuristic(name: str, problem, *, with_generator: bool = True):
    compiled = compile_problem(problem)
    generator = ActionGenerator(problem, compiled.checker) if with_generator else None
    return make_heuristic(name, compiled, generator)


def particles(problem, jitter: float = 0.0, seed: int = 0, **poses) -> ParticleBelief:
    """A belief of PARTICLES states around ``poses``, each coordinate within +-``jitter``."""
    rng = np.random.default_rng(seed)
    states = []
    for _ in range(PARTICLES):
        moved = {
            name: tuple(v + rng.uniform(-jitter, jitter) for v in pose)
            for name, pose in poses.items()
        }
        states.append(WorldState.from_mapping(problem, moved))
    return ParticleBelief(tuple(states))


def at_goal(problem, jitter: float = 0.05) -> ParticleBelief:
    return particles(problem, jitter, **{p: problem.goal.target(p) for p in problem.goal.parts})


# -- every heuristic -----------------------------------------------------------------------
def test_an_unknown_name_is_refused_with_the_known_ones():
    with pytest.raises(ValueError, match="unknown heuristic 'greedy'.*inadmissible, admissible"):
        heuristic("greedy", tiny("one-block"))


@pytest.mark.parametrize("name", HEURISTICS)
@pytest.mark.parametrize(
    "problem", ["one-block", "two-blocks-row", "l-part", "millimetres"], indirect=True
)
def test_every_heuristic_is_zero_at_a_goal_belief(name, problem):
    belief = at_goal(problem)
    assert GoalTest(problem).satisfied_array(belief.poses, belief.names())
    value = heuristic(name, problem)(belief)
    if name == "manhattan":  # the particles' jitter, nothing more
        assert 0.0 <= value <= 2 * 0.05 * len(problem.goal.parts)
    elif name == "inadmissible":  # a count of 0 and the tie-breaker of that jitter
        assert 0.0 <= value < 0.01
    else:
        assert value == 0.0


@pytest.mark.parametrize("name", HEURISTICS)
def test_every_heuristic_is_zero_at_a_relative_goal(name):
    problem = tiny("relative-goal")
    turn = 0.6
    c, s = math.cos(turn), math.sin(turn)
    belief = particles(problem, T=(5.0, 5.0, turn), U=(5.0 + 2.0 * c, 5.0 + 2.0 * s, turn))
    assert heuristic(name, problem)(belief) == pytest.approx(0.0, abs=1e-9)


@pytest.mark.parametrize("name", HEURISTICS)
def test_every_heuristic_is_finite_and_non_negative_at_the_start(name):
    for problem_name in ("one-block", "two-blocks-row", "block-and-fixture", "obstacle"):
        problem = tiny(problem_name)
        start = ParticleBelief(
            (WorldState(tuple((i.name, i.pose) for i in problem.initial)),) * PARTICLES
        )
        value = heuristic(name, problem)(start)
        assert math.isfinite(value) and value >= 0.0


def test_blind_is_zero_everywhere():
    problem = tiny("two-blocks-row")
    h = heuristic("blind", problem)
    assert h(particles(problem, A=(1.0, 4.0, 0.0))) == 0.0
    reversed_row = particles(problem, A=(6.0, 1.0, 0.0), B=(8.0, 1.0, 0.0))
    assert h(reversed_row) == 0.0  # not even the ordering filter


def test_manhattan_sums_centre_distances_to_the_targets():
    problem = tiny("two-blocks-row")  # goal A (9.5, 0.5), B (8.5, 0.5)
    h = heuristic("manhattan", problem)
    both = particles(problem, A=(7.5, 2.0, 0.3), B=(8.0, 0.5, 0.0))
    assert h(both) == pytest.approx((2.0 + 1.5) + 0.5)
    # The centre is the middle of the particles' span, not their mean.
    one = tiny("one-block")  # goal A (4.5, 0.5)
    spread = ParticleBelief(
        tuple(WorldState((("A", (x, 0.5, 0.0)),)) for x in (2.0, 2.1, 2.2, 2.3, 4.0))
    )
    assert heuristic("manhattan", one)(spread) == pytest.approx(4.5 - 3.0)


def test_manhattan_is_zero_while_a_goal_part_is_off_the_table():
    # Current behaviour, pinned because the planner's tie-breaker (and so its plans) depends
    # on it: with a goal part off the table there are no goal coordinates at all, so the parts
    # already on the table do not count either.
    problem = tiny("two-blocks-row")
    assert heuristic("manhattan", problem)(particles(problem, A=(7.5, 2.0, 0.0))) == 0.0


def test_manhattan_of_a_relative_goal_is_measured_in_the_reference_frame():
    problem = tiny("relative-goal")  # U at (2, 0) in T's frame
    h = heuristic("manhattan", problem)
    # T turned a quarter: U should be at T + (0, 2); it is at T + (1, 2).
    belief = particles(problem, T=(5.0, 5.0, math.pi / 2), U=(6.0, 7.0, math.pi / 2))
    assert h(belief) == pytest.approx(1.0)


def test_admissible_counts_the_parts_still_to_place():
    problem = tiny("two-blocks-row")
    h = heuristic("admissible", problem)
    assert h(ParticleBelief((WorldState(()),))) == 2.0
    assert h(particles(problem, A=(3.0, 3.0, 0.0))) == 1.0
    assert h(particles(problem, A=(3.0, 3.0, 0.0), B=(1.0, 3.0, 0.0))) == 0.0


def test_inadmissible_is_the_count_plus_a_tie_breaker_below_one():
    problem = tiny("two-blocks-row")
    goal = GoalTest(problem)
    h = heuristic("inadmissible", problem)
    near = particles(problem, A=(9.5, 1.5, 0.0), B=(8.5, 0.5, 0.0))
    far = particles(problem, A=(9.5, 3.5, 0.0), B=(8.5, 0.5, 0.0))
    assert per_dimension_count(goal, near) == per_dimension_count(goal, far) == 1
    assert 1.0 < h(near) < h(far) < 2.0
    # Even the farthest belief stays below the next unit of the count.
    corner = particles(problem, A=(0.5, 4.5, 0.0), B=(0.5, 0.5, 0.0))
    assert per_dimension_count(goal, corner) == 3 and 3.0 < h(corner) < 4.0


def test_per_dimension_count_matches_thesis_cases():
    p = tiny("two-blocks-row")
    goal = GoalTest(p)
    frame = AngleFrame.of(p)

    def belief(*states):
        return ParticleBelief(tuple(frame.canonical(WorldState(s)) for s in states))

    # Both off the table: 2 + 2.
    assert per_dimension_count(goal, belief(())) == 4
    # A inside in x and y, B off table: 0 + 2.
    assert per_dimension_count(goal, belief((("A", (9.5, 0.5, 0.0)),))) == 2
    # A outside in y only: 1 + 2.
    assert per_dimension_count(goal, belief((("A", (9.5, 1.0, 0.0)),))) == 3
    # A's x interval (over two particles) sticks out of the goal interval: 1 + 2.
    assert (
        per_dimension_count(goal, belief((("A", (9.5, 0.5, 0.0)),), (("A", (9.0, 0.5, 0.0)),))) == 3
    )
    # A inside in x and y but turned beyond the angle tolerance: 1 + 2.
    assert per_dimension_count(goal, belief((("A", (9.5, 0.5, math.radians(30))),))) == 3


def test_per_dimension_count_of_a_relative_goal_needs_the_reference():
    problem = tiny("relative-goal")
    goal = GoalTest(problem)
    u_only = particles(problem, U=(8.0, 8.0, 0.0))
    assert per_dimension_count(goal, u_only) == 2  # as if U were off the table too
    both = particles(problem, T=(4.0, 4.0, 0.0), U=(6.0, 7.0, 0.0))  # right x, wrong y
    assert per_dimension_count(goal, both) == 1


# -- the ordering filter -------------------------------------------------------------------
def test_ordering_filter_flags_reversed_row():
    h = make_heuristic("inadmissible", compile_problem(tiny("two-blocks-row")))
    # Goal: B left of A on the bottom row. Reversed in the same row -> infinite.
    reversed_row = ParticleBelief((WorldState((("A", (6.0, 1.0, 0.0)), ("B", (8.0, 1.0, 0.0)))),))
    assert h(reversed_row) == math.inf
    # Same order, or not in the same row -> finite.
    fine = ParticleBelief((WorldState((("A", (8.0, 1.0, 0.0)), ("B", (6.0, 1.0, 0.0)))),))
    apart = ParticleBelief((WorldState((("A", (6.0, 1.0, 0.0)), ("B", (8.0, 3.5, 0.0)))),))
    assert math.isfinite(h(fine)) and math.isfinite(h(apart))


@pytest.mark.parametrize("name", HEURISTICS)
def test_a_reversed_row_is_infinite_for_the_filtered_heuristics_only(name):
    problem = tiny("two-blocks-row")
    reversed_row = particles(problem, 0.02, A=(6.0, 1.0, 0.0), B=(8.0, 1.0, 0.0))
    value = heuristic(name, problem)(reversed_row)
    if name in ("ordering", "admissible", "inadmissible"):
        assert value == math.inf
    else:
        assert math.isfinite(value)


def test_the_ordering_filter_ignores_relative_goals():
    problem = tiny("relative-goal")  # U must end right of T, wherever T is
    left_of = particles(problem, T=(8.0, 5.0, 0.0), U=(4.0, 5.0, 0.0))
    assert heuristic("ordering", problem)(left_of) == 0.0


@pytest.fixture(scope="module")
def tight_offsets():
    """two-blocks-row whose B may be placed only where A's goal footprint reaches."""
    return with_planning("two-blocks-row", "{place_offsets: [[0, 0.4], [0.4, 0.4]]}")


def test_a_part_walled_in_by_a_part_placed_out_of_order_is_infinite(tight_offsets):
    h = heuristic("ordering", tight_offsets)
    # A already at its goal covers every place candidate of B for good.
    assert h(particles(tight_offsets, 0.02, A=(9.5, 0.5, 0.0))) == math.inf
    # A elsewhere: B can still be placed (A only moves towards its goal, but not across B).
    assert h(particles(tight_offsets, 0.02, A=(5.0, 3.0, 0.0))) == 0.0
    # Without the planner's action generator this part of the filter is off.
    unaware = heuristic("ordering", tight_offsets, with_generator=False)
    assert unaware(particles(tight_offsets, 0.02, A=(9.5, 0.5, 0.0))) == 0.0


def test_two_parts_off_the_table_that_fit_in_neither_order_are_infinite():
    # blocks-9-square with its third column (C, F, I) and top row (G, H) built: the corner
    # pocket A, B, D, E is closed. A placed first walls in B (B's only open candidates reach A's
    # goal cell), B placed first walls in A, and likewise for the other pairs.
    problem = arrange_up.load("blocks-9-square")
    h = heuristic("ordering", problem)
    built = {p: problem.goal.target(p) for p in "CFGHI"}
    assert h(particles(problem, 0.01, **built)) == math.inf
    # Built from the corner outwards (the bottom row first), every pair still has an order.
    row = {p: problem.goal.target(p) for p in "ABC"}
    assert h(particles(problem, 0.01, **row)) == 0.0
    # C built before B closes B's cell: B between A's goal and C fits in neither order with A.
    assert h(particles(problem, 0.01, C=row["C"])) == math.inf
    # The empty table: the corner is filled from the walls outwards.
    assert h(ParticleBelief((WorldState.from_mapping(problem, {}),))) == 0.0
