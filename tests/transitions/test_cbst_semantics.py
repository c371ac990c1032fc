"""The "cbst" semantics: interval beliefs, place/pick/push, symmetry, planning with it."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from arrange_up.belief.goals import GoalTest
from arrange_up.belief.states import IntervalBelief
from arrange_up.cbst.features import BUCKLE_LIMIT
from arrange_up.evaluation.rollouts import execute_plan
from arrange_up.io.domains import load as load_domain
from arrange_up.io.domains import resolve_problem
from arrange_up.io.yaml_problem import load_problem_text
from arrange_up.model.problem import Controller, ControllerKind, InitialObject
from arrange_up.model.world import Pick, Place, Push, WorldState
from arrange_up.planning.planner import plan
from arrange_up.transitions import available, make_semantics
from arrange_up.transitions.cbst import GRAZE_ALLOWANCE, CBSTSemantics

SERVO = Controller(kind=ControllerKind.SERVO)


def load(name: str):
    """A shipped problem under the servo controller: these tests pin the semantics with the
    servo's model, which plans the block worlds (docs/cbst.md: the compliant one does not)."""
    return dataclasses.replace(load_domain(name), controller=SERVO)


PLACE_HALF = (0.2, 0.2, round(math.radians(15), 6))


@pytest.fixture(scope="module")
def blocks1():
    return load("blocks-1")


@pytest.fixture(scope="module")
def sem(blocks1):
    return CBSTSemantics(blocks1)


def _push_toward(direction: str, center, distance: float = 20.0, gap: float = 0.4) -> Push:
    """A paddle push along ``direction`` starting ``gap`` behind a block at ``center``."""
    ux, uy = {"+x": (1, 0), "-x": (-1, 0), "+y": (0, 1), "-y": (0, -1)}[direction]
    theta = math.atan2(uy, ux) - 0.5 * math.pi  # the paddle pushes along its own +y
    back = 0.5 + gap + 0.075
    pose = (center[0] - ux * back, center[1] - uy * back, theta)
    return Push("paddle", pose, distance)


def test_registered_and_built_by_name(blocks1):
    assert "cbst" in available()
    model = make_semantics("cbst", blocks1)
    assert isinstance(model, CBSTSemantics) and model.name == "cbst"
    assert model.particles == 2 and model.simulations == 0


def test_initial_belief_is_the_problems_intervals(blocks1):
    problem = dataclasses.replace(
        blocks1, initial=(InitialObject("A", (5.0, 2.5, math.radians(95)), (0.1, 0.2, 0.05)),)
    )
    belief = CBSTSemantics(problem).initial_belief()
    assert isinstance(belief, IntervalBelief) and belief.names() == ("A",)
    iv = belief.get("A")
    # Angles are wrapped into the square's 90-degree period around the goal angle 0.
    assert iv.center == pytest.approx((5.0, 2.5, math.radians(5)), abs=1e-6)
    assert iv.half == (0.1, 0.2, 0.05)
    assert belief.poses.shape == (2, 1, 3)


def test_place_and_pick(sem):
    b0 = sem.initial_belief()
    b1 = sem.apply(b0, Place("A", (5.0, 2.5, 0.0)))
    assert b1.get("A").center == (5.0, 2.5, 0.0) and b1.get("A").half == PLACE_HALF
    # Canonical: the same outcome reached twice is equal and hashes equal.
    again = sem.apply(b0, Place("A", (5.0000000001, 2.5, 0.0)))
    assert again == b1 and hash(again) == hash(b1)
    assert sem.apply(b1, Pick("A")) == b0


def test_push_touching_nothing_returns_the_belief(sem):
    b = sem.apply(sem.initial_belief(), Place("A", (5.0, 2.5, 0.0)))
    far = Push("paddle", (2.0, 0.8, -0.5 * math.pi), 1.0)  # below A's row, short
    assert sem.apply(b, far) is b


def test_push_not_axis_aligned_is_refused(sem):
    b = sem.apply(sem.initial_belief(), Place("A", (5.0, 2.5, 0.0)))
    assert sem.apply(b, Push("paddle", (3.5, 2.5, -1.2), 5.0)) is None
    assert sem.reasons["the push is not axis-aligned"] >= 1


def test_push_short_of_the_wall_is_refused(sem):
    b = sem.apply(sem.initial_belief(), Place("A", (5.0, 2.5, 0.0)))
    assert sem.apply(b, _push_toward("+x", (5.0, 2.5), distance=1.5)) is None


@pytest.mark.parametrize("direction", ["+x", "-x", "+y", "-y"])
def test_push_against_each_wall_is_the_same_prediction(sem, direction):
    """One implementation for four directions: pushing a block against each wall gives the
    same interval in the canonical frame (flush at x_max = wall - d/2)."""
    center = (5.0, 2.5)
    b = sem.apply(sem.initial_belief(), Place("A", (*center, 0.0)))
    out = sem.apply(b, _push_toward(direction, center))
    assert out is not None
    iv = out.get("A")
    axis = 0 if direction in ("+x", "-x") else 1
    sign = 1 if direction[0] == "+" else -1
    wall = (10.0 if axis == 0 else 5.0) if sign > 0 else 0.0
    flush = wall - sign * 0.5
    along_low, along_high = sorted((iv.low[axis], iv.high[axis]))
    # The wall-side end is x_max plus max(slip, allowance): at most BUCKLE_LIMIT beyond it.
    end = along_high if sign > 0 else along_low
    assert -1e-6 <= sign * (end - flush) <= BUCKLE_LIMIT + 1e-6
    assert sign * (flush - (along_low if sign > 0 else along_high)) > 0
    # Across the push: the centre is unchanged.
    assert iv.center[1 - axis] == pytest.approx(center[1 - axis], abs=1e-6)
    # The same numbers in every direction (halves along / across the push).
    along, across = iv.half[axis], iv.half[1 - axis]
    reference = sem.apply(b, _push_toward("+x", center)).get("A")
    assert (along, across, iv.half[2]) == pytest.approx(
        (reference.half[0], reference.half[1], reference.half[2]), abs=2e-6
    )
    assert iv.center[2] == 0.0


def test_two_block_train_composes_from_the_wall(sem):
    problem = load("blocks-2")
    s = CBSTSemantics(problem)
    b = IntervalBelief(
        (
            ("A", s._interval("A", (9.49, 0.55, 0.0), (0.01, 0.05, 0.05))),
            ("B", s._interval("B", (8.3, 0.6, 0.0), (0.1, 0.1, 0.1))),
        )
    )
    out = s.apply(b, _push_toward("+x", (8.3, 0.6)))
    assert out is not None and s.simulations == 2
    a, bb = out.get("A"), out.get("B")
    # Composed from the wall: A flush at 9.5, B flush against A at 8.5 (up to the slip).
    assert 9.5 + s.allowance(1) - 1e-6 <= a.high[0] <= 9.5 + BUCKLE_LIMIT
    assert 8.5 + s.allowance(2) - 1e-6 <= bb.high[0] <= 8.5 + BUCKLE_LIMIT
    assert bb.low[0] < 8.5 and a.low[0] < 9.5


def _outcomes(problem, belief, push, n, seed=0):
    """``n`` simulated outcomes of ``push`` from states drawn uniformly from ``belief``."""
    from arrange_up.geometry.collision import CollisionChecker
    from arrange_up.model.world import draw_noise
    from arrange_up.physics.simulation import simulate

    checker, rng, out = CollisionChecker(problem), np.random.default_rng(seed), []

    def draw(iv):
        return tuple(iv.center[i] + rng.uniform(-1, 1) * iv.half[i] for i in range(3))

    while len(out) < n:
        state = WorldState.from_mapping(problem, {k: draw(iv) for k, iv in belief.objects})
        if not checker.state_collides(state):
            outcome = simulate(problem, state, push, draw_noise(problem, push, rng))
            assert outcome.ok
            out.append(outcome.state.as_dict())
    return out


def test_predicted_boxes_contain_simulated_outcomes():
    """Conservativeness on the blocks-3 case of a two-row push: B compressed against A in
    row 1 while C, flush in row 2, may be grazed. Every simulated outcome lies in the box
    (within 0.005 in / 0.5 degree, the physics' contact slop). Under the servo, the controller
    the model was trained in."""
    problem = load("blocks-3")
    s = CBSTSemantics(problem)
    b = IntervalBelief(
        (
            ("A", s._interval("A", (9.494504, 0.541542, 0.0), (0.011496, 0.041542, 0.043264))),
            ("B", s._interval("B", (8.088, 0.505916, 0.0), (0.287, 0.011916, 0.049))),
            ("C", s._interval("C", (9.494719, 1.493477, 0.0), (0.011281, 0.090993, 0.042396))),
        )
    )
    push = Push("paddle", (7.067304, 1.322212, -0.5 * math.pi), 2.8577)
    post = s.apply(b, push)
    assert post is not None
    tol = np.array([0.005, 0.005, math.radians(0.5)])
    for outcome in _outcomes(problem, b, push, 40):
        for name, iv in post.objects:
            pose = np.array(outcome[name])
            pose[2] = iv.center[2] + ((pose[2] - iv.center[2] + math.pi / 4) % (math.pi / 2))
            pose[2] -= math.pi / 4
            assert np.all(pose >= np.array(iv.low) - tol), (name, pose, iv)
            assert np.all(pose <= np.array(iv.high) + tol), (name, pose, iv)


def test_a_grazed_block_is_widened_across_by_at_most_the_allowance(monkeypatch):
    """A grazed block (C, flush in row 2, while B is pushed against A in row 1) is widened
    across the push by the grazer's overlap, but by no more than the controller's allowance."""
    problem = load("blocks-3")
    half_c = (0.011281, 0.090993, 0.042396)
    belief = IntervalBelief(
        (
            (
                "A",
                CBSTSemantics(problem)._interval(
                    "A", (9.494504, 0.541542, 0.0), (0.011496, 0.041542, 0.043264)
                ),
            ),
            (
                "B",
                CBSTSemantics(problem)._interval(
                    "B", (8.088, 0.700916, 0.0), (0.287, 0.011916, 0.049)
                ),
            ),
            ("C", CBSTSemantics(problem)._interval("C", (9.494719, 1.493477, 0.0), half_c)),
        )
    )
    push = Push("paddle", (7.067304, 1.522212, -0.5 * math.pi), 2.8577)

    def widened(allowance: float) -> float:
        monkeypatch.setitem(GRAZE_ALLOWANCE, ControllerKind.SERVO, allowance)
        post = CBSTSemantics(problem).apply(belief, push)
        assert post is not None
        return post.get("C").half[1] - half_c[1]

    overlap = widened(math.inf)  # the grazer's overlap alone
    assert overlap > 0.05
    assert widened(0.05) == pytest.approx(0.05, abs=2e-6)
    assert widened(1.0) == pytest.approx(overlap, abs=2e-6)


def _simulate_plan(problem, actions, seed: int) -> WorldState | None:
    rng = np.random.default_rng(seed)
    run = execute_plan(problem, WorldState(()), actions, rng)
    return run.state if run.ok else None


@pytest.mark.parametrize("name", ["blocks-1", "blocks-2"])
def test_plans_end_to_end(name):
    problem = load(name)
    result = plan(problem, semantics="cbst", timeout=60)
    assert result.solved, result.stats
    final = result.beliefs[-1]
    goal = GoalTest(problem)
    assert goal.satisfied_array(final.poses, final.names())
    assert result.stats["transitions_simulated"] > 0
    # The plan is conformant in simulation too (a few noisy rollouts).
    for seed in range(5):
        state = _simulate_plan(problem, result.actions, seed)
        assert state is not None and goal.satisfied(state)


def test_plans_a_row_of_four_against_a_wall():
    # Each new block's push down clips the block beside it unless the paddle is moved clear;
    # before the action generator offered that position, this row had no CBST plan at all.
    text = resolve_problem("blocks-4").read_text(encoding="utf-8")
    text = text.replace("C: [9.5, 1.5, 0]", "C: [7.5, 0.5, 0]").replace(
        "D: [8.5, 1.5, 0]", "D: [6.5, 0.5, 0]"
    )
    problem = dataclasses.replace(load_problem_text(text, "row-of-four.yaml"), controller=SERVO)
    assert [problem.goal.target(n)[:2] for n in "ABCD"] == [
        (9.5, 0.5),
        (8.5, 0.5),
        (7.5, 0.5),
        (6.5, 0.5),
    ]
    result = plan(problem, semantics="cbst", timeout=60)
    assert result.solved, result.stats
    goal = GoalTest(problem)
    for seed in range(3):
        state = _simulate_plan(problem, result.actions, seed)
        assert state is not None and goal.satisfied(state)
