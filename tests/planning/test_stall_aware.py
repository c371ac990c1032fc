"""Push distances that know the compliant controller stalls: nominal plans still reach goals
that do not lie against a wall."""

from __future__ import annotations

import math
from dataclasses import replace

import arrange_up
from arrange_up.belief.goals import GoalTest
from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.model.problem import Controller, ControllerKind
from arrange_up.model.world import Push, WorldState
from arrange_up.physics.simulation import simulate
from arrange_up.planning.actions import ActionGenerator

COMPLIANT = Controller(kind=ControllerKind.COMPLIANT)


def _run(problem, actions) -> WorldState:
    state = WorldState(tuple((o.name, o.pose) for o in problem.initial))
    for action in actions:
        state = simulate(problem, state, action).state
    return state


def test_compliant_nominal_plan_pushes_further_and_reaches_the_goal():
    servo = arrange_up.load("tt-mating")  # a relative goal in the open: no wall to push to
    compliant = replace(servo, controller=COMPLIANT)
    servo_plan = arrange_up.plan(servo, semantics="deterministic")
    plan = arrange_up.plan(compliant, semantics="deterministic")
    assert plan.status.value == "solved"
    # The servo's plan falls short under the compliant controller; the compliant plan does not.
    assert GoalTest(compliant).misses(_run(compliant, servo_plan.actions))
    assert not GoalTest(compliant).misses(_run(compliant, plan.actions))
    first = [a.distance for a in plan.actions if isinstance(a, Push)][0]
    servo_first = [a.distance for a in servo_plan.actions if isinstance(a, Push)][0]
    assert first > servo_first


def test_servo_distances_are_unchanged_by_the_solver():
    problem = arrange_up.load("blocks-2")
    explicit = replace(problem, controller=Controller(kind=ControllerKind.SERVO))
    a = arrange_up.plan(problem, semantics="deterministic")
    b = arrange_up.plan(explicit, semantics="deterministic")
    assert a.actions == b.actions and a.stats["expanded"] == b.stats["expanded"]


def test_a_train_already_within_its_goal_is_not_pushed_to_the_wall_again():
    # Under the compliant controller a repeated push into a wall perturbs the train (a new
    # belief each time, where the servo's repeat is an exact duplicate): it is not offered once
    # every part it drives lies within its goal interval along the push.
    servo = arrange_up.load("blocks-2")
    compliant = replace(servo, controller=COMPLIANT)

    def pushes_right(problem, a_x: float) -> list[Push]:
        none = (0.0, 0.0, 0.0)
        belief = IntervalBelief(
            (
                ("A", ObjectInterval((a_x, 0.5, 0.0), none)),
                ("B", ObjectInterval((a_x - 1.0, 0.5, 0.0), none)),
            )
        )
        generator = ActionGenerator(problem, CollisionChecker(problem))
        return [p for p in generator.pushes(belief) if p.pose[2] == -math.pi / 2]

    target = servo.goal.target("A")[0]
    assert pushes_right(servo, target - 0.01)  # the servo's repeat is offered (and is a no-op)
    assert not pushes_right(compliant, target - 0.01)
    # A train short of its goal interval is pushed to the wall under either controller.
    assert pushes_right(compliant, target - 0.4)
