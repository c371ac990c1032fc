"""Mates of a relative goal (arrange_up.planning.mating) and the pushes the action generator
offers for them: brought beside the mate with clearance, then seated against it."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from catalogue import particle_task, servo

import arrange_up
from arrange_up.belief.goals import GoalTest
from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.io.yaml_problem import load_problem, load_problem_text
from arrange_up.physics.stall import wall_overdrive
from arrange_up.planning.actions import ActionGenerator
from arrange_up.planning.mating import Mates

#: B's goal: flush against A's right face (A is the reference).
PAIR = """
name: pair
table: {size: [10, 6], walls: []}
objects:
  A: {kind: part, shape: {box: [1, 1]}}
  B: {kind: part, shape: {box: [1, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
initial:
  A: {pose: [3, 3, 0], uncertainty: [0.05, 0.05, 2]}
  B: {pose: [6, 3, 0], uncertainty: [0.05, 0.05, 2]}
goal:
  tolerance: [0.3, 0.3, 15]
  relative: {reference: A, poses: {B: [1.0, 0.0, 0]}}
uncertainty: {place: [0.2, 0.2, 15], push: [0.05, 0.05, 3]}
"""
PADDLE_HALF_THICKNESS = 0.075
MINUS_X = math.pi / 2  # the paddle's angle when it pushes along -x


def pair_belief(b_x: float, half=(0.05, 0.05, 0.03), b_y: float = 3.5) -> IntervalBelief:
    """A at its initial pose; B at ``b_x`` and ``b_y`` (by default 0.5 in above its goal's y,
    beyond the tolerance: it has yet to come down beside A)."""
    return IntervalBelief(
        (
            ("A", ObjectInterval((3.0, 3.0, 0.0), (0.05, 0.05, 0.03))),
            ("B", ObjectInterval((b_x, b_y, 0.0), half)),
        )
    )


def west_pushes(gen: ActionGenerator, belief: IntervalBelief):
    return sorted(
        (p for p in gen.pushes(belief) if math.isclose(p.pose[2], MINUS_X)),
        key=lambda p: p.distance,
    )


def test_the_mate_is_ahead_where_the_goal_footprints_touch():
    tz = arrange_up.load("tz-mating")
    mates = Mates(tz)
    t_pose = (3.5, 8.0, 0.0)
    z_goal = (3.5 + 1.5, 8.0 - 0.4, math.pi / 2)  # the goal's Z pose in the world
    # The upright Z sits in the notch under the T's bar, beside its stem: the T lies ahead of
    # it leftwards (the stem) and upwards (the bar), nowhere else.
    ahead = {
        name
        for name, (axis, sign) in {"+x": (0, 1), "-x": (0, -1), "+y": (1, 1), "-y": (1, -1)}.items()
        if mates.ahead("Z", z_goal, t_pose, axis, sign)
    }
    assert ahead == {"-x", "+y"}
    assert not mates.ahead("T", t_pose, t_pose, 0, -1)  # the reference has no mate
    assert not Mates(arrange_up.load("blocks-4"))  # an absolute goal has none


def test_a_part_is_brought_beside_its_mate_with_clearance_and_seated_against_it():
    problem = load_problem_text(PAIR, "pair.yaml")
    gen = ActionGenerator(problem, CollisionChecker(problem), solve_distances=False)
    pushes = west_pushes(gen, pair_belief(6.0))
    assert len(pushes) == 3  # with clearance, to the goal coordinate, seating
    (pose,) = {p.pose for p in pushes}
    # Where each push would send the paddle's front, against the goal coordinate of B's rear
    # (A's right face, x = 3.5) and the compliant stall of B alone.
    fronts = [pose[0] - PADDLE_HALF_THICKNESS - p.distance for p in pushes]
    stall = gen.stall.stall("B", pair_belief(6.0), 0, -1)
    u = problem.uncertainty
    over = wall_overdrive(problem.controller, u.friction, u.part_density, 1.0, u.push[0])
    assert fronts == pytest.approx([4.8 - stall, 4.5 - stall, 4.5 - over], abs=1e-3)
    assert over > stall
    # B spread wider than the tolerance relative to A (0.4 + 0.05 in): stopped short by that.
    wide = pair_belief(6.0, (0.4, 0.05, 0.03))
    stall_wide = gen.stall.stall("B", wide, 0, -1)
    first = west_pushes(gen, wide)[0]
    front = first.pose[0] - PADDLE_HALF_THICKNESS - first.distance
    assert front == pytest.approx(4.5 + 0.45 - stall_wide, abs=1e-3)
    # Level with A already (within its goal interval in y): no push that stops with clearance.
    level = west_pushes(gen, pair_belief(6.0, b_y=3.0))
    assert [pose[0] - PADDLE_HALF_THICKNESS - p.distance for p in level] == pytest.approx(
        [4.5 - stall, 4.5 - over], abs=1e-3
    )


def test_a_seated_part_is_not_pressed_again_and_the_servo_is_never_overdriven():
    problem = load_problem_text(PAIR, "pair.yaml")
    gen = ActionGenerator(problem, CollisionChecker(problem), solve_distances=False)
    # B beside its goal with clearance (0.25 in to the right): the push to the goal coordinate
    # and the seating push, not one with clearance (it would not move B).
    beside = pair_belief(4.25, (0.1, 0.05, 0.03))
    assert len(west_pushes(gen, beside)) == 2
    # B inside its goal interval along x: nothing along -x.
    assert west_pushes(gen, pair_belief(4.05)) == []
    # The servo ends where it is sent: its push to the goal coordinate is its seating push.
    servo_gen = ActionGenerator(servo(problem), CollisionChecker(problem), solve_distances=False)
    assert len(west_pushes(servo_gen, pair_belief(6.0))) == 2  # with clearance, to the goal
    assert len(west_pushes(servo_gen, beside)) == 1


def test_the_tz_mating_is_planned_with_particles():
    # Before the mates, the 10-particle search was exhausted after 126 nodes: every push of the
    # Z to its goal coordinate jammed some particles against the end of the T's bar.
    problem = arrange_up.load("tz-mating")
    result = arrange_up.plan(problem, particles=10, workers=1, max_nodes=300)
    assert result.solved, result.reason
    final = result.beliefs[-1]
    assert GoalTest(problem).satisfied_array(final.poses, final.names())


def test_a_reference_wider_than_the_tolerance_is_gathered_to_an_edge():
    problem = load_problem_text(PAIR, "pair.yaml")
    gen = ActionGenerator(problem, CollisionChecker(problem), solve_distances=False)
    b = ObjectInterval((6.0, 3.5, 0.0), (0.05, 0.05, 0.03))
    wide = IntervalBelief((("A", ObjectInterval((3.0, 3.0, 0.0), (0.4, 0.05, 0.03))), ("B", b)))
    (push,) = [p for p in gen.pushes(wide) if math.isclose(p.pose[2], -math.pi / 2)]  # +x
    # The paddle's front ends where A's rear would be had its centre moved by its half-width
    # (every state swept to x = 3.4), plus the stall.
    front = push.pose[0] + PADDLE_HALF_THICKNESS + push.distance
    assert front == pytest.approx(3.4 - 0.5 + gen.stall.stall("A", wide, 0, 1), abs=1e-3)
    # A within the tolerance (+-0.3 in): not gathered; B is not the reference.
    narrow = pair_belief(6.0)
    assert not any(math.isclose(p.pose[1], 3.0) for p in gen.pushes(narrow))
    assert Mates(problem).gather("A", 0.3, 0) is None
    assert Mates(problem).gather("B", 0.4, 0) is None


def test_create_a_t_is_planned_by_gathering_its_top_bar():
    # The top bar starts +-0.35 in wide in x against a tolerance of +-0.25: before the bar
    # could be gathered the 25-particle search was exhausted (277 nodes, the stem missing x).
    problem = arrange_up.load("create-a-t")
    result = arrange_up.plan(problem, particles=25, workers=1, max_nodes=300)
    assert result.solved, result.reason
    moved_top = [
        b.intervals.get("top").center != a.intervals.get("top").center
        for a, b in zip(result.beliefs, result.beliefs[1:], strict=False)
    ]
    assert any(moved_top)


def test_a_turned_reference_whose_angle_spread_moves_its_mates_targets_is_squared():
    # m-rotated-reference-pair: the bar R starts turned 30 degrees +-5; at 8.5 cm its mates'
    # targets move +-7.4 mm with that spread, which with R's own +-5 mm exceeds the +-8 mm
    # tolerance (its position spread alone would not).
    path = (
        Path(__file__).resolve().parents[1] / "problems" / "fresh" / "m-rotated-reference-pair.yaml"
    )
    problem = load_problem(path)
    mates = Mates(problem)
    mm = 1.0 / 25.4
    assert mates.square("R", (5 * mm, 5 * mm, math.radians(5)))
    assert not mates.square("R", (5 * mm, 5 * mm, math.radians(0.5)))
    assert not mates.square("R", (9 * mm, 5 * mm, math.radians(5)))  # gathering's case
    assert not mates.square("A", (5 * mm, 5 * mm, math.radians(5)))
    squared = []
    with particle_task(problem, 10) as task:
        for edge in task.successors(task.initial_belief()):
            child = edge.make_child()
            if child is not None:
                theta = child.poses[:, child.names().index("R"), 2]
                squared.append(float(np.abs(theta).max()))
    # a press on one side against a wall turns it flat in every particle
    assert min(squared) < math.radians(3)
