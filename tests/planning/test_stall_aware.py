"""Push distances that know the compliant controller stalls: nominal plans still reach goals
that do not lie against a wall."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import pytest

import arrange_up
import arrange_up.physics.simulation as physics
from arrange_up.belief.goals import GoalTest
from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.io.yaml_problem import load_problem_text
from arrange_up.model.problem import SERVO_CONTROLLER, Controller, ControllerKind
from arrange_up.model.world import Push, WorldState
from arrange_up.physics.simulation import simulate
from arrange_up.physics.stall import WALL_MARGIN, wall_overdrive
from arrange_up.planning.actions import ActionGenerator

COMPLIANT = Controller(kind=ControllerKind.COMPLIANT)
GOLDENS = Path(__file__).parents[1] / "goldens"
DOMAINS = Path(__file__).parents[2] / "domains"


def _run(problem, actions) -> WorldState:
    state = WorldState(tuple((o.name, o.pose) for o in problem.initial))
    for action in actions:
        state = simulate(problem, state, action).state
    return state


def test_compliant_nominal_plan_pushes_further_and_reaches_the_goal():
    compliant = arrange_up.load("tt-mating")  # a relative goal in the open: no wall to push to
    servo = replace(compliant, controller=SERVO_CONTROLLER)
    assert compliant.controller == COMPLIANT  # the default
    servo_plan = arrange_up.plan(servo, semantics="deterministic")
    plan = arrange_up.plan(compliant, semantics="deterministic")
    assert plan.status.value == "solved"
    # The servo's plan falls short under the compliant controller; the compliant plan does not.
    assert GoalTest(compliant).misses(_run(compliant, servo_plan.actions))
    assert not GoalTest(compliant).misses(_run(compliant, plan.actions))
    first = [a.distance for a in plan.actions if isinstance(a, Push)][0]
    servo_first = [a.distance for a in servo_plan.actions if isinstance(a, Push)][0]
    assert first > servo_first


def test_a_file_that_names_the_servo_plans_as_the_servo_always_did():
    # The servo's distances are the generator's geometric ones (no stall, no solver): blocks-2
    # with `controller: {kind: servo}` plans as tests/goldens/servo-blocks-2-deterministic.json.
    text = (DOMAINS / "blocks-2.yaml").read_text(encoding="utf-8")
    problem = load_problem_text(text + "controller: {kind: servo}\n")
    golden = json.loads((GOLDENS / "servo-blocks-2-deterministic.json").read_text())
    result = arrange_up.plan(problem, semantics="deterministic")
    pushes = [a.distance for a in result.actions if isinstance(a, Push)]
    assert pushes == [a["distance"] for a in golden["actions"] if a["type"] == "Push"]


def test_a_train_already_within_its_goal_is_not_pushed_to_the_wall_again():
    # Under the compliant controller a repeated push into a wall perturbs the train (a new
    # belief each time, where the servo's repeat is an exact duplicate): it is not offered once
    # every part it drives lies within its goal interval along the push.
    compliant = arrange_up.load("blocks-2")
    servo = replace(compliant, controller=SERVO_CONTROLLER)

    def pushes_right(problem, a_x: float, **options) -> list[Push]:
        none = (0.0, 0.0, 0.0)
        belief = IntervalBelief(
            (
                ("A", ObjectInterval((a_x, 0.5, 0.0), none)),
                ("B", ObjectInterval((a_x - 1.0, 0.5, 0.0), none)),
            )
        )
        generator = ActionGenerator(problem, CollisionChecker(problem), **options)
        return [p for p in generator.pushes(belief) if p.pose[2] == -math.pi / 2]

    target = servo.goal.target("A")[0]
    assert pushes_right(servo, target - 0.01)  # the servo's repeat is offered (and is a no-op)
    assert not pushes_right(compliant, target - 0.01)
    # A semantics that predicts rather than simulates (CBST) keeps it: it narrows intervals.
    assert pushes_right(compliant, target - 0.01, settled_wall_pushes=True)
    # A train short of its goal interval is pushed to the wall under either controller.
    assert pushes_right(compliant, target - 0.4)


def test_cbst_pushes_to_a_wall_stop_just_past_the_compressed_train():
    # A set point at the wall is a train length past where the compliant paddle stops, so it
    # presses the train with the force clip and buckles it; with compressed_wall_pushes (what
    # the planner gives CBST) the paddle's front is sent past the compressed train by its
    # worst-case stall, its pose uncertainty along the push and WALL_MARGIN only.
    compliant = arrange_up.load("blocks-2")
    servo = replace(compliant, controller=SERVO_CONTROLLER)
    none = (0.0, 0.0, 0.0)
    belief = IntervalBelief(
        (
            ("A", ObjectInterval((9.3, 0.5, 0.0), none)),
            ("B", ObjectInterval((7.0, 0.5, 0.0), none)),
        )
    )

    def fronts_of_b_right(problem, **options) -> set[float]:
        generator = ActionGenerator(problem, CollisionChecker(problem), **options)
        return {
            round(p.pose[0] + 0.075 + p.distance, 4)  # the paddle's front at the set point
            for p in generator.pushes(belief)
            if p.pose[2] == -math.pi / 2 and p.pose[0] < 7.0
        }

    wall = 10.0
    # worst-case stall of two 1-inch blocks (mu 0.55, density 0.15, Kp 300), the push's
    # +-0.05 in along x, and the margin
    overdrive = 0.55 * 386.09 * 0.15 * 2.0 / 300.0 + 0.05 + WALL_MARGIN
    assert overdrive == pytest.approx(
        wall_overdrive(COMPLIANT, (0.25, 0.55), (0.1, 0.15), 2.0, 0.05), abs=1e-12
    )
    assert wall in fronts_of_b_right(compliant)
    compressed = fronts_of_b_right(compliant, compressed_wall_pushes=True)
    assert wall not in compressed
    assert any(abs(f - (wall - 2.0 + overdrive)) < 1e-3 for f in compressed)
    # The servo's pushes to the wall go to the wall either way.
    assert wall in fronts_of_b_right(servo, compressed_wall_pushes=True)


def test_cbst_gets_the_stall_lengthened_distances_without_simulating_them(monkeypatch):
    # A semantics that does not simulate pushes (CBST) only predicts pushes that compress a
    # train against a wall, so solving a push's distance in simulations (the compliant
    # controller's goal-coordinate pushes) is turned off for it: the distance is the free
    # travel plus the nominal stall, and nothing is simulated.
    compliant = arrange_up.load("blocks-2")
    belief = IntervalBelief((("A", ObjectInterval((7.0, 0.5, 0.0), (0.0, 0.0, 0.0))),))
    calls = []
    real = physics.simulate
    monkeypatch.setattr(physics, "simulate", lambda *a, **k: calls.append(1) or real(*a, **k))

    def rightwards(**options) -> set[float]:
        generator = ActionGenerator(compliant, CollisionChecker(compliant), **options)
        return {p.distance for p in generator.pushes(belief) if p.pose[2] == -math.pi / 2}

    solved = rightwards()
    assert calls
    calls.clear()
    unsolved = rightwards(solve_distances=False)
    assert not calls
    generator = ActionGenerator(compliant, CollisionChecker(compliant))
    stall = generator.stall.per_area * 1.0  # A alone, 1 square inch
    (pose_x,) = {p.pose[0] for p in generator.pushes(belief) if p.pose[2] == -math.pi / 2}
    to_goal = (7.0 - 0.5) - (pose_x + 0.075) + (9.5 - 7.0) + stall
    assert any(abs(d - to_goal) < 1e-3 for d in unsolved)
    assert unsolved != solved
