"""Push distances that know the compliant controller stalls: nominal plans still reach goals
that do not lie against a wall."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import arrange_up
from arrange_up.belief.goals import GoalTest
from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.io.yaml_problem import load_problem_text
from arrange_up.model.problem import SERVO_CONTROLLER, Controller, ControllerKind
from arrange_up.model.world import Push, WorldState
from arrange_up.physics.simulation import simulate
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
