"""Beliefs and goal tests on catalogue problems and small hand-made cases (the heuristics and
the action generator are tested in tests/planning)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from catalogue import tiny

from arrange_up.belief.compiled import compile_problem
from arrange_up.belief.goals import GoalTest
from arrange_up.belief.states import (
    IntervalBelief,
    ObjectInterval,
    ParticleBelief,
    dominates,
    sample_initial_particles,
    symmetry_period,
    wrap_angle,
)
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import Shape
from arrange_up.model.world import WorldState


def square(side: float = 1.0) -> Shape:
    h = side / 2
    return Shape((((-h, -h), (h, -h), (h, h), (-h, h)),))


def test_symmetry_periods():
    assert symmetry_period(square()) == pytest.approx(math.pi / 2)
    rect = Shape((((-1.0, -0.5), (1.0, -0.5), (1.0, 0.5), (-1.0, 0.5)),))
    assert symmetry_period(rect) == pytest.approx(math.pi)
    tee = tiny("relative-goal").object("T").shape
    assert symmetry_period(tee) == pytest.approx(2 * math.pi)


def test_wrap_angle_into_half_open_period():
    assert wrap_angle(math.radians(91), 0.0, math.pi / 2) == pytest.approx(math.radians(1))
    assert wrap_angle(math.radians(-46), 0.0, math.pi / 2) == pytest.approx(math.radians(44))
    assert wrap_angle(3 * math.pi, 0.0, 2 * math.pi) == pytest.approx(-math.pi)


def test_absolute_goal_accepts_symmetric_turn_and_rejects_excess():
    p = tiny("two-blocks-row")
    goal = GoalTest(p)
    ok = WorldState((("A", (9.45, 0.55, math.radians(90 + 5))), ("B", (8.5, 0.5, 0.0))))
    assert goal.satisfied(ok)
    bad = WorldState((("A", (9.45, 0.85, 0.0)), ("B", (8.5, 0.5, math.radians(20)))))
    assert not goal.satisfied(bad)
    misses = {m.part: m.dimensions() for m in goal.misses(bad)}
    assert misses == {"A": ("y",), "B": ("theta",)}
    missing = WorldState((("A", (9.5, 0.5, 0.0)),))
    assert [m.dimensions() for m in goal.misses(missing)] == [("off table",)]


def test_a_part_on_the_table_that_misses_is_reported_while_another_is_off_it():
    # The planner's reason line ("the best belief still misses ...") listed only the parts off
    # the table while any was, as if those on it were at their goals.
    goal = GoalTest(tiny("two-blocks-row"))
    astray = WorldState((("A", (9.5, 1.0, 0.0)),))  # B off the table, A 0.5 in too high
    misses = [(m.part, m.dimensions()) for m in goal.misses(astray)]
    assert misses == [("B", ("off table",)), ("A", ("y",))]
    assert goal.misses(astray)[1].excess == pytest.approx((0.0, 0.3, 0.0))


def test_a_relative_goals_mates_are_judged_only_with_their_reference_on_the_table():
    goal = GoalTest(tiny("relative-goal"))
    alone = WorldState((("U", (3.0, 3.0, 0.0)),))
    assert [(m.part, m.dimensions()) for m in goal.misses(alone)] == [("T", ("off table",))]
    far = WorldState((("T", (3.0, 3.0, 0.0)),))
    assert [(m.part, m.dimensions()) for m in goal.misses(far)] == [("U", ("off table",))]


def test_relative_goal_is_invariant_to_moving_the_pair():
    p = tiny("relative-goal")
    goal = GoalTest(p)
    for x, y, turn in [(3.0, 3.0, 0.0), (6.0, 2.0, 0.7), (5.0, 9.0, -2.0)]:
        c, s = math.cos(turn), math.sin(turn)
        u = (x + 2.0 * c, y + 2.0 * s, turn)
        assert goal.satisfied(WorldState((("T", (x, y, turn)), ("U", u))))
        far = (x + 2.3 * c, y + 2.3 * s, turn)
        assert not goal.satisfied(WorldState((("T", (x, y, turn)), ("U", far))))


def test_particle_belief_goal_needs_every_particle():
    p = tiny("two-blocks-row")
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
    p = tiny("relative-goal")
    checker = CollisionChecker(p)
    a = sample_initial_particles(compile_problem(p), 20, np.random.default_rng(3))
    b = sample_initial_particles(compile_problem(p), 20, np.random.default_rng(3))
    assert a == b
    assert not any(checker.state_collides(s) for s in a.particles)
    poses = a.poses
    assert np.all(np.abs(poses[:, 0, :2] - [4, 4]) <= 0.3 + 1e-12)


def test_particle_belief_stores_an_array_and_rebuilds_equal_world_states() -> None:
    states = (
        WorldState((("A", (1.0, 2.0, 0.5)), ("B", (3.0, 4.0, -0.0)))),
        WorldState((("A", (1.5, 2.0, 0.25)), ("B", (3.0, 4.5, 0.0)))),
    )
    belief = ParticleBelief(states)
    assert belief.particles == states
    assert belief.names() == ("A", "B") and len(belief) == 2
    assert belief.poses.shape == (2, 2, 3) and not belief.poses.flags.writeable
    # -0.0 == 0.0, so beliefs that differ only in a zero's sign are equal and hash equal.
    same = ParticleBelief(
        (states[0], WorldState((("A", (1.5, 2.0, 0.25)), ("B", (3.0, 4.5, -0.0)))))
    )
    assert same == belief and hash(same) == hash(belief)
    moved = ParticleBelief(
        (states[0], WorldState((("A", (1.5, 2.0, 0.25)), ("B", (3.0, 4.5, 1e-300)))))
    )
    assert moved != belief
    renamed = ParticleBelief(tuple(WorldState((("C", s.poses[0][1]), s.poses[1])) for s in states))
    assert renamed != belief
    with pytest.raises(ValueError, match="at least one particle"):
        ParticleBelief(())
