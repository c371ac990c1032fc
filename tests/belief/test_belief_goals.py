"""Beliefs, goal tests, heuristics and action generators on small hand-made cases."""

from __future__ import annotations

import math

import numpy as np
import pytest

from arrange_up.belief.goals import GoalTest
from arrange_up.belief.states import (
    AngleFrame,
    IntervalBelief,
    ObjectInterval,
    ParticleBelief,
    dominates,
    sample_initial_particles,
    symmetry_period,
    wrap_angle,
)
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.io.yaml_problem import load_problem_text
from arrange_up.model.problem import Shape
from arrange_up.model.world import Place, Push, WorldState
from arrange_up.planning.actions import ActionGenerator
from arrange_up.planning.heuristics import make_heuristic, per_dimension_count

BLOCKS_2 = """
name: two-blocks
table: {size: [10, 5]}
objects:
  A: {kind: part, shape: {box: [1, 1]}}
  B: {kind: part, shape: {box: [1, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
goal:
  tolerance: [0.2, 0.2, 15]
  poses: {A: [9.5, 0.5, 0], B: [8.5, 0.5, 0]}
uncertainty: {place: [0.2, 0.2, 15], push: [0.05, 0.05, 3]}
"""

TEE_PAIR = """
name: tee-pair
table: {size: [12, 12], walls: []}
shapes:
  tee: {polygon: [[0,0],[3,0],[3,1],[2,1],[2,3],[1,3],[1,1],[0,1]]}
objects:
  T: {kind: part, shape: tee}
  U: {kind: part, shape: {box: [1, 1]}}
initial:
  T: {pose: [4, 4, 0], uncertainty: [0.3, 0.3, 5]}
  U: {pose: [8, 8, 0], uncertainty: [0.3, 0.3, 5]}
goal:
  tolerance: [0.1, 0.1, 5]
  relative: {reference: T, poses: {U: [2.0, 0.0, 0]}}
"""


def problem(text: str):
    return load_problem_text(text, "test.yaml")


def square(side: float = 1.0) -> Shape:
    h = side / 2
    return Shape((((-h, -h), (h, -h), (h, h), (-h, h)),))


def test_symmetry_periods():
    assert symmetry_period(square()) == pytest.approx(math.pi / 2)
    rect = Shape((((-1.0, -0.5), (1.0, -0.5), (1.0, 0.5), (-1.0, 0.5)),))
    assert symmetry_period(rect) == pytest.approx(math.pi)
    tee = problem(TEE_PAIR).object("T").shape
    assert symmetry_period(tee) == pytest.approx(2 * math.pi)


def test_wrap_angle_into_half_open_period():
    assert wrap_angle(math.radians(91), 0.0, math.pi / 2) == pytest.approx(math.radians(1))
    assert wrap_angle(math.radians(-46), 0.0, math.pi / 2) == pytest.approx(math.radians(44))
    assert wrap_angle(3 * math.pi, 0.0, 2 * math.pi) == pytest.approx(-math.pi)


def test_absolute_goal_accepts_symmetric_turn_and_rejects_excess():
    p = problem(BLOCKS_2)
    goal = GoalTest(p)
    ok = WorldState((("A", (9.45, 0.55, math.radians(90 + 5))), ("B", (8.5, 0.5, 0.0))))
    assert goal.satisfied(ok)
    bad = WorldState((("A", (9.45, 0.85, 0.0)), ("B", (8.5, 0.5, math.radians(20)))))
    assert not goal.satisfied(bad)
    misses = {m.part: m.dimensions() for m in goal.misses(bad)}
    assert misses == {"A": ("y",), "B": ("theta",)}
    missing = WorldState((("A", (9.5, 0.5, 0.0)),))
    assert [m.dimensions() for m in goal.misses(missing)] == [("off table",)]


def test_relative_goal_is_invariant_to_moving_the_pair():
    p = problem(TEE_PAIR)
    goal = GoalTest(p)
    for x, y, turn in [(3.0, 3.0, 0.0), (6.0, 2.0, 0.7), (5.0, 9.0, -2.0)]:
        c, s = math.cos(turn), math.sin(turn)
        u = (x + 2.0 * c, y + 2.0 * s, turn)
        assert goal.satisfied(WorldState((("T", (x, y, turn)), ("U", u))))
        far = (x + 2.3 * c, y + 2.3 * s, turn)
        assert not goal.satisfied(WorldState((("T", (x, y, turn)), ("U", far))))


def test_particle_belief_goal_needs_every_particle():
    p = problem(BLOCKS_2)
    goal = GoalTest(p)
    good = WorldState((("A", (9.5, 0.5, 0.0)), ("B", (8.5, 0.5, 0.0))))
    off = WorldState((("A", (9.0, 0.5, 0.0)), ("B", (8.5, 0.5, 0.0))))
    assert goal.satisfied_array(ParticleBelief((good, good)).poses, ("A", "B"))
    assert not goal.satisfied_array(ParticleBelief((good, off)).poses, ("A", "B"))


def test_interval_fit_and_domination():
    s1 = WorldState((("A", (1.0, 2.0, 0.0)),))
    s2 = WorldState((("A", (1.4, 2.2, 0.1)),))
    fitted = ParticleBelief((s1, s2)).intervals.get("A")
    assert fitted.center == pytest.approx((1.2, 2.1, 0.05))
    assert fitted.half == pytest.approx((0.2, 0.1, 0.05))
    small = IntervalBelief((("A", ObjectInterval((1.2, 2.1, 0.0), (0.1, 0.05, 0.01))),))
    large = IntervalBelief((("A", ObjectInterval((1.2, 2.1, 0.0), (0.3, 0.2, 0.1))),))
    other = IntervalBelief((("B", ObjectInterval((1.2, 2.1, 0.0), (0.3, 0.2, 0.1))),))
    assert dominates(small, large)
    assert not dominates(large, small)
    assert not dominates(small, other)  # different objects never dominate


def test_initial_particles_are_collision_free_and_reproducible():
    p = problem(TEE_PAIR)
    checker = CollisionChecker(p)
    a = sample_initial_particles(p, 20, np.random.default_rng(3))
    b = sample_initial_particles(p, 20, np.random.default_rng(3))
    assert a == b
    assert not any(checker.state_collides(s) for s in a.particles)
    poses = a.poses
    assert np.all(np.abs(poses[:, 0, :2] - [4, 4]) <= 0.3 + 1e-12)


def test_per_dimension_count_matches_thesis_cases():
    p = problem(BLOCKS_2)
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


def test_ordering_filter_flags_reversed_row():
    p = problem(BLOCKS_2)
    checker = CollisionChecker(p)
    goal = GoalTest(p)
    h = make_heuristic("inadmissible", p, goal, checker)
    # Goal: B left of A on the bottom row. Reversed in the same row -> infinite.
    reversed_row = ParticleBelief((WorldState((("A", (6.0, 1.0, 0.0)), ("B", (8.0, 1.0, 0.0)))),))
    assert h(reversed_row) == math.inf
    # Same order, or not in the same row -> finite.
    fine = ParticleBelief((WorldState((("A", (8.0, 1.0, 0.0)), ("B", (6.0, 1.0, 0.0)))),))
    apart = ParticleBelief((WorldState((("A", (6.0, 1.0, 0.0)), ("B", (8.0, 3.5, 0.0)))),))
    assert math.isfinite(h(fine)) and math.isfinite(h(apart))


def test_generated_actions_satisfy_their_preconditions():
    p = problem(BLOCKS_2)
    checker = CollisionChecker(p)
    generator = ActionGenerator(p, checker)
    empty = IntervalBelief(())
    places = generator.places(empty)
    assert {a.obj for a in places} == {"A", "B"}
    for action in places:
        assert checker.shadow_inside_table(action.obj, action.pose, p.uncertainty.place)
        assert not checker.shadow_hits_fixed(action.obj, action.pose, p.uncertainty.place)
    a_placed = IntervalBelief((("A", ObjectInterval((9.088, 0.912, 0.0), p.uncertainty.place)),))
    pushes = generator.pushes(a_placed)
    assert pushes and all(isinstance(a, Push) for a in pushes)
    directions = set()
    for push in pushes:
        shadows = [("A", (9.088, 0.912, 0.0), p.uncertainty.place)]
        assert checker.shadow_clear("paddle", push.pose, p.uncertainty.push, shadows)
        directions.add(round(push.pose[2], 3))
    # Against the right and bottom walls only +x (theta -pi/2) and -y (theta pi) fit.
    assert directions == {round(-math.pi / 2, 3), round(-math.pi, 3)}
    # A push towards the wall and one to the goal coordinate are both offered.
    assert len({p.distance for p in pushes if round(p.pose[2], 3) == round(-math.pi / 2, 3)}) == 2


def test_place_candidates_for_relative_goal_follow_reference():
    p = problem(TEE_PAIR.replace("  U: {pose: [8, 8, 0], uncertainty: [0.3, 0.3, 5]}\n", ""))
    generator = ActionGenerator(p, CollisionChecker(p))
    t = IntervalBelief((("T", ObjectInterval((4.0, 4.0, math.pi / 2), (0.0, 0.0, 0.0))),))
    target = generator.place_target("U", t)
    assert target == pytest.approx((4.0, 6.0, math.pi / 2))
    assert all(isinstance(a, Place) and a.obj == "U" for a in generator.places(t))


def test_push_that_clips_a_neighbour_is_also_offered_clear_of_it():
    # A row of three blocks ends at C; D has just been placed beside it. Pushing D down from a
    # paddle centred on D clips the side of C's shadow (the paddle may or may not touch C), so
    # with unclipped_pushes the same push is offered a second time from where the paddle misses
    # C or covers it whole.
    p = problem(BLOCKS_2)
    checker = CollisionChecker(p)
    generator = ActionGenerator(p, checker, unclipped_pushes=True)
    c_iv = ObjectInterval((7.513, 0.564, 0.0), (0.027, 0.064, math.radians(3.2)))
    d_iv = ObjectInterval((6.088, 0.912, 0.0), p.uncertainty.place)
    belief = IntervalBelief((("A", c_iv), ("B", d_iv)))
    half = 0.5 * 2.5  # the paddle's half length

    def centres_pushing_d_down(belief, generator=generator):
        # Pushes down (theta -pi) whose paddle covers D's centre with 0.1 in to spare.
        return sorted(
            {
                a.pose[0]
                for a in generator.pushes(belief)
                if round(a.pose[2], 3) == round(-math.pi, 3) and abs(a.pose[0] - 6.088) < half
            }
        )

    centres = centres_pushing_d_down(belief)
    assert len(centres) == 2
    assert 6.088 in centres  # the first stays centred on the pushed block
    c_low, _, c_high, _ = checker.shadow_box("A", c_iv.center, c_iv.half)
    assert c_low < 6.088 + half < c_high  # ... and clips C
    (clear,) = [x for x in centres if x != 6.088]
    missed = clear + half <= c_low
    covered = clear - half <= c_low and clear + half >= c_high
    assert missed or covered
    assert abs(clear - 6.088) <= half - 0.1
    # Nothing ahead to clip: one position only.
    assert centres_pushing_d_down(IntervalBelief((("B", d_iv),))) == [6.088]
    # Off by default (particle semantics simulate clipped contacts): one position only.
    assert centres_pushing_d_down(belief, ActionGenerator(p, checker)) == [6.088]
