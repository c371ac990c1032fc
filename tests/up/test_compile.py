"""Tests of the unified-planning model of a problem (``arrange_up.up.compile``, ``up_effects``)."""

from __future__ import annotations

import dataclasses
import math
import warnings
from fractions import Fraction
from pathlib import Path

import pytest
from unified_planning.engines.plan_validator import SequentialPlanValidator
from unified_planning.engines.results import ValidationResultStatus
from unified_planning.engines.sequential_simulator import UPSequentialSimulator
from unified_planning.plans import ActionInstance, SequentialPlan

import arrange_up
from arrange_up.io.domains import load
from arrange_up.io.yaml_problem import load_problem
from arrange_up.model.problem import Goal, ObjectKind, ObjectSpec, problem_hash
from arrange_up.model.world import Pick, Place, Push
from arrange_up.up.compile import (
    from_up,
    made_by_to_up,
    plan_from_up,
    plan_to_up,
    to_up,
)
from arrange_up.up.effects import exact, exact_degrees


def _names(items) -> set[str]:
    return {item.name for item in items}


def _simulator(up_problem) -> UPSequentialSimulator:
    # the factory's simulator refuses real action parameters; the class itself handles them
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return UPSequentialSimulator(up_problem, error_on_failed_checks=False)


def test_structure_of_an_absolute_goal_problem():
    problem = load("blocks-2")
    up = to_up(problem)
    assert up.name == "blocks-2"
    assert _names(up.user_types) == {"movable", "placeable", "part", "manipulator"}
    assert _names(up.fluents) == {"on_table", "x", "y", "theta"}
    assert all(f.type.is_real_type() for f in up.fluents if f.name != "on_table")
    assert [a.name for a in up.actions] == ["place", "push", "pick"]
    place, push, pick = up.actions
    assert [p.name for p in place.parameters] == ["o", "px", "py", "ptheta"]
    assert str(place.parameters[0].type) == "placeable - movable"
    assert all(p.type.is_real_type() for p in place.parameters[1:])
    assert [p.name for p in push.parameters] == ["m", "px", "py", "ptheta", "distance"]
    assert [str(c) for c in place.preconditions] == ["(not on_table(o))"]
    assert [str(c) for c in push.preconditions] == ["(not on_table(m))"]
    assert [str(c) for c in pick.preconditions] == ["on_table(o)"]
    assert place.simulated_effect is not None and push.simulated_effect is not None
    # per part: on_table and two bounds on each of x, y, theta
    assert len(up.goals) == 2 * 7
    assert up.explicit_initial_values == {}  # every block starts off the table
    assert {"SIMULATED_EFFECTS", "REAL_ACTION_PARAMETERS"} <= set(up.kind.features)


def test_goal_bounds_are_exact_inches_and_degrees():
    up = to_up(load("blocks-1"))
    text = {str(g) for g in up.goals}
    assert {"(93/10 <= x(A))", "(x(A) <= 97/10)", "(-15 <= theta(A))", "(theta(A) <= 15)"} <= text


def test_any_angle_tolerance_has_no_theta_condition():
    problem = load("blocks-2")
    any_angle = dataclasses.replace(
        problem, goal=dataclasses.replace(problem.goal, tolerance=(0.2, 0.2, None))
    )
    goals = [str(g) for g in to_up(any_angle).goals]
    assert len(goals) == 2 * 5
    assert not any("theta" in g for g in goals)


def test_relative_goal_fluents_and_wrapped_initial_angles():
    up = to_up(load("tz-mating"))
    assert {"rel_x", "rel_y", "rel_theta"} <= _names(up.fluents)
    assert "obstacle" not in _names(up.user_types)
    values = {str(k): v.constant_value() for k, v in up.explicit_initial_values.items()}
    # T at (3.5, 8, 0), Z at (8.5, 4, 90 deg); a Z looks the same after a half turn, so its
    # angle is stored in the half-open period centred on its start angle: [0, 180) holds 90.
    # Z in T's frame: (5, -4), 90 deg around the target 90.
    assert values["theta(Z)"] == 90
    assert (values["rel_x(Z)"], values["rel_y(Z)"], values["rel_theta(Z)"]) == (5, -4, 90)
    assert all(isinstance(v, Fraction | bool) for v in values.values())
    # on_table of the reference and of the part, two bounds on each relative coordinate,
    # and the bar fixture, which starts off the table, off it again
    assert len(up.goals) == 2 + 6 + 1
    assert str(up.goals[-1]) == "(not on_table(bar))"
    assert "(80 <= rel_theta(Z))" in {str(g) for g in up.goals}


def test_simulated_effects_return_exact_fractions():
    up = to_up(load("blocks-1"))
    em = up.environment.expression_manager
    simulator = _simulator(up)
    start = simulator.get_initial_state()
    place = up.action("place")
    params = (
        up.object("A"),
        em.Real(Fraction("9.1")),
        em.Real(Fraction("0.9")),
        em.Real(Fraction(0)),
    )
    after = simulator.apply(start, place, params)
    assert after is not None
    assert after.get_value(up.fluent("x")(up.object("A"))).constant_value() == Fraction("9.1")
    assert after.get_value(up.fluent("on_table")(up.object("A"))).bool_constant_value()
    # the effect function itself, as UP calls it
    function = place.simulated_effect.function
    values = function(up, start, dict(zip(place.parameters, params, strict=True)))
    assert [v.constant_value() for v in values] == [Fraction("9.1"), Fraction("0.9"), 0]
    assert all(type(v.constant_value()) is Fraction for v in values)


def test_a_push_that_fails_makes_the_plan_invalid():
    problem = load("down-push")  # no walls: a long push drives the block off the table
    up = to_up(problem)
    plan = plan_to_up(up, [Push("paddle", (6.0, 6.8, math.pi), 9.0)])
    result = SequentialPlanValidator().validate(up, plan)
    assert result.status is ValidationResultStatus.INVALID
    assert "fails under the 'deterministic' semantics" in result.log_messages[0].message


def test_a_fence_the_plan_puts_down_must_be_picked_up_for_the_up_goal():
    fresh = Path(__file__).parents[1] / "problems" / "fresh" / "fence-corner.yaml"
    problem = load_problem(fresh)
    result = arrange_up.plan(problem, semantics="deterministic")
    assert result.solved and result.actions[-1] == Pick("bar")
    up = to_up(problem)
    assert "(not on_table(bar))" in {str(g) for g in up.goals}
    whole = SequentialPlanValidator().validate(up, plan_to_up(up, result.actions))
    assert whole.status is ValidationResultStatus.VALID
    left = SequentialPlanValidator().validate(up, plan_to_up(up, result.actions[:-1]))
    assert left.status is ValidationResultStatus.INVALID


def test_exact_numbers_are_decimal_fractions():
    assert exact(2.8) == Fraction(14, 5)
    assert exact(0.1 + 0.2) == Fraction(3, 10)
    assert exact_degrees(math.pi / 2) == 90


def test_from_up_gives_the_same_problem_back():
    problem = load("blocks-2")
    up = to_up(problem)
    assert made_by_to_up(up)
    assert problem_hash(from_up(up)) == problem_hash(problem)
    assert from_up(up.clone()) is problem
    edited = up.clone()
    edited.add_goal(up.fluent("on_table")(up.object("paddle")))
    with pytest.raises(ValueError, match="edited since"):
        from_up(edited)


def test_two_compilations_give_equal_actions():
    problem = load("blocks-1")
    assert to_up(problem).action("push") == to_up(problem).action("push")


def test_to_up_refuses_semantics_it_cannot_compile():
    with pytest.raises(ValueError, match="cannot be compiled"):
        to_up(load("blocks-1"), semantics="particles")
    to_up(load("blocks-1"), semantics="nominal")  # an alias of deterministic


def test_to_up_refuses_names_that_clash_with_the_vocabulary():
    problem = load("blocks-1")
    a = problem.object("A")
    clash = dataclasses.replace(
        problem,
        objects=(ObjectSpec("x", ObjectKind.PART, a.shape), *problem.objects[1:]),
        goal=Goal((("x", (9.5, 0.5, 0.0)),), problem.goal.tolerance),
    )
    with pytest.raises(ValueError, match="'x' clash"):
        to_up(clash)


def test_plans_convert_both_ways():
    up = to_up(load("down-push"))
    actions = (
        Place("bar", (6.0, 2.0, 0.0)),
        Push("paddle", (6.0, 6.8, math.pi), 1.5),
        Pick("bar"),
    )
    plan = plan_to_up(up, actions)
    assert isinstance(plan, SequentialPlan)
    assert all(isinstance(a, ActionInstance) for a in plan.actions)
    assert plan.actions[1].actual_parameters[3].constant_value() == 180
    back = plan_from_up(plan)
    assert back[0] == actions[0] and back[2] == actions[2]
    assert back[1].pose == pytest.approx(actions[1].pose) and back[1].distance == 1.5


def test_actions_of_the_same_problem_from_yaml_and_pddl_are_equal():
    from arrange_up.io.domains import domains_dir
    from arrange_up.io.pddl import load_pddl_problem

    from_pddl = load_pddl_problem(domains_dir() / "blocks-1.pddl")
    assert to_up(from_pddl).action("place") == to_up(load("blocks-1")).action("place")


def test_from_up_refuses_every_example_problem_of_unified_planning_with_value_error():
    from unified_planning.test.examples import get_example_problems

    for case in get_example_problems().values():
        with pytest.raises(ValueError):  # ProblemFormatError included; never another error
            from_up(case.problem)
    scheduling = get_example_problems()["sched:basic"].problem
    with pytest.raises(ValueError, match="a unified-planning SchedulingProblem is not an arrange"):
        from_up(scheduling)


def test_plan_from_up_names_objects_as_the_problem_does():
    """PDDL names are case-insensitive: a plan over lowercase names reads against the problem's
    written case, and an exact name wins."""
    problem = load("blocks-2")  # A, B, paddle
    lower = dataclasses.replace(
        problem,
        objects=tuple(dataclasses.replace(s, name=s.name.lower()) for s in problem.objects),
        initial=tuple(dataclasses.replace(e, name=e.name.lower()) for e in problem.initial),
        goal=dataclasses.replace(
            problem.goal, targets=tuple((p.lower(), t) for p, t in problem.goal.targets)
        ),
    )
    up = to_up(lower)
    plan = plan_to_up(up, [Place("a", (1.0, 1.0, 0.0)), Pick("b")])
    assert [a.obj for a in plan_from_up(plan)] == ["a", "b"]
    assert [a.obj for a in plan_from_up(plan, problem)] == ["A", "B"]
    assert [a.obj for a in plan_from_up(plan, lower)] == ["a", "b"]
    two = dataclasses.replace(
        problem, objects=(*problem.objects, dataclasses.replace(problem.objects[0], name="a"))
    )
    assert [a.obj for a in plan_from_up(plan, two)] == ["a", "B"]
    both = dataclasses.replace(
        problem,
        objects=tuple(
            dataclasses.replace(s, name=n)
            for s, n in zip(problem.objects, ["A", "b", "B"], strict=True)
        ),
    )
    assert [a.obj for a in plan_from_up(plan, both)] == ["A", "b"]


def test_pddl_writer_writes_plans_with_real_parameters_and_others_unchanged():
    from fractions import Fraction

    from unified_planning.io import PDDLReader, PDDLWriter
    from unified_planning.plans import ActionInstance, SequentialPlan

    import arrange_up.up.planner_engine  # noqa: F401  (installs the writer's extension)
    from arrange_up.io.domains import domains_dir
    from arrange_up.io.pddl import domain_path
    from arrange_up.up.plan_writer import decimal

    assert [decimal(Fraction(v)) for v in ("8.066637", "-90", "0", "1/3")] == [
        "8.066637",
        "-90",
        "0",
        "0.333333333333",
    ]
    problem = to_up(load("blocks-1"))
    plan = SequentialPlan(
        [
            ActionInstance(
                problem.action("place"),
                [problem.object("A"), Fraction("9.088"), Fraction("0.912"), Fraction(-15)],
            ),
            ActionInstance(problem.action("pick"), [problem.object("A")]),
        ]
    )
    assert PDDLWriter(problem).get_plan(plan) == "(place a 9.088 0.912 -15)\n(pick a)\n"
    read = PDDLReader().parse_problem(str(domain_path()), str(domains_dir() / "blocks-1.pddl"))
    objects_only = SequentialPlan([ActionInstance(read.action("pick"), [read.object("a")])])
    assert PDDLWriter(read).get_plan(objects_only) == "(pick a)\n"  # unified-planning's own
