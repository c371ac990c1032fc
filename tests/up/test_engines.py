"""Tests of the unified-planning engine ``arrange-up`` and its registration."""

from __future__ import annotations

import importlib
import io
import pickle
import runpy
import subprocess
import sys
import warnings
from fractions import Fraction
from pathlib import Path

import pytest
from catalogue import tiny
from unified_planning.engines import OptimalityGuarantee
from unified_planning.engines import PlanGenerationResultStatus as Status
from unified_planning.engines.results import ValidationResultStatus
from unified_planning.environment import get_environment
from unified_planning.io import PDDLReader
from unified_planning.model import ProblemKind
from unified_planning.shortcuts import OneshotPlanner, PlanRepairer, PlanValidator

import arrange_up.up.registration as registration
from arrange_up.io.domains import domains_dir, load
from arrange_up.io.pddl import domain_path
from arrange_up.io.yaml_problem import check_problem_text
from arrange_up.up.compile import from_up, to_up
from arrange_up.up.planner_engine import ArrangeUpPlanner
from arrange_up.up.repairer_engine import ArrangeUpFixtureRepairer
from arrange_up.up.validator_engine import ArrangeUpReliability

registration.register()  # idempotent; works before or after unified_planning is imported

DETERMINISTIC = {"semantics": "deterministic", "seed": 0}
ROLLOUTS = {"rollouts": 8, "seed": 0, "workers": 1}
ROOT = Path(__file__).resolve().parents[2]


def _solve(problem, params=None, **kwargs):
    with OneshotPlanner(name="arrange-up", params=params or DETERMINISTIC) as planner:
        return planner.solve(problem, **kwargs)


@pytest.mark.parametrize("name", ["blocks-1", "blocks-2"])
def test_plans_are_solved_exact_and_accepted_by_ups_validator(name):
    problem = to_up(load(name))
    result = _solve(problem, timeout=60)
    assert result.status is Status.SOLVED_SATISFICING
    assert result.engine_name == "arrange-up"
    assert int(result.metrics["expanded"]) >= 1 and "generated" in result.metrics
    for instance in result.plan.actions:
        for param in instance.actual_parameters[1:]:
            value = param.constant_value()
            assert isinstance(value, Fraction)
            assert 10**9 % value.denominator == 0  # a decimal, not a binary fraction
    with PlanValidator(name="sequential_plan_validator") as validator:
        check = validator.validate(problem, result.plan)
    assert check.status is ValidationResultStatus.VALID


def test_node_limit_is_reported_honestly():
    result = _solve(to_up(load("blocks-2")), {**DETERMINISTIC, "max_nodes": 1})
    assert result.status is Status.UNSOLVABLE_INCOMPLETELY
    assert result.plan is None
    assert "node limit of 1" in result.log_messages[0].message
    assert result.metrics["status"] == "node-limit"
    assert all(type(value) is str for value in result.metrics.values())  # not an enum


def test_the_engine_enforces_the_timeout():
    result = _solve(to_up(load("blocks-2")), timeout=1e-6)
    assert result.status is Status.TIMEOUT
    assert result.plan is None


def test_a_problem_read_from_pddl_is_solved():
    path = domains_dir() / "blocks-1.pddl"
    up = PDDLReader().parse_problem(str(domain_path()), str(path))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # its kind is supported: unified-planning does not warn
        result = _solve(up)
    assert result.status is Status.SOLVED_SATISFICING
    assert "came from PDDL" in result.log_messages[0].message
    with PlanValidator(name="sequential_plan_validator") as validator:
        check = validator.validate(up, result.plan)
    assert check.status is ValidationResultStatus.VALID


@pytest.mark.parametrize(
    ("old", "new"), [("(:action push", "(:action shove"), ("(:action pick", "(:action lift")]
)
def test_a_problem_read_with_another_domain_is_unsupported(tmp_path, old, new):
    # its actions are not the ones the planner plans: a plan of push(...) would name an action
    # the domain does not have
    domain = tmp_path / "other-domain.pddl"
    domain.write_text(domain_path().read_text().replace(old, new))
    up = PDDLReader().parse_problem(str(domain), str(domains_dir() / "blocks-1.pddl"))
    result = _solve(up)
    assert result.status is Status.UNSUPPORTED_PROBLEM and result.plan is None
    assert "was read with another domain than arrange-up's" in result.log_messages[0].message


def test_a_foreign_problem_is_unsupported():
    from unified_planning.shortcuts import BoolType, Fluent, InstantaneousAction, Problem

    problem = Problem("lights")
    on = Fluent("on", BoolType())
    switch = InstantaneousAction("switch")
    switch.add_effect(on, True)
    problem.add_fluent(on, default_initial_value=False)
    problem.add_action(switch)
    problem.add_goal(on)
    with pytest.warns(UserWarning, match="cannot establish whether arrange-up can solve"):
        result = _solve(problem)
    assert result.status is Status.UNSUPPORTED_PROBLEM
    assert "not an arrange-up problem" in result.log_messages[0].message


def test_an_ignored_heuristic_warns():
    stream = io.StringIO()
    with pytest.warns(UserWarning, match="ignores the heuristic"):
        result = _solve(to_up(load("blocks-1")), heuristic=lambda state: 0, output_stream=stream)
    assert result.status is Status.SOLVED_SATISFICING


def test_parameters_are_checked():
    with pytest.raises(ValueError, match="unknown semantics 'nope'"):
        OneshotPlanner(name="arrange-up", params={"semantics": "nope"})
    with pytest.raises(ValueError, match="particles must be a positive integer"):
        OneshotPlanner(name="arrange-up", params={"particles": 0})
    with pytest.raises(ValueError, match="validate must be a non-negative integer"):
        OneshotPlanner(name="arrange-up", params={"validate": -1})
    with pytest.raises(ValueError, match="validate must be a non-negative integer"):
        OneshotPlanner(name="arrange-up", params={"semantics": "cbst", "validate": 2.5})
    # a negative seed, for every engine and semantics, when the engine is made
    for make, engine in (
        (OneshotPlanner, "arrange-up"),
        (PlanValidator, "arrange-up-reliability"),
        (PlanRepairer, "arrange-up-fixtures"),
    ):
        with pytest.raises(ValueError, match=f"{engine}: seed must be a non-negative integer"):
            make(name=engine, params={"seed": -1})
    with pytest.raises(ValueError, match="arrange-up: seed must be a non-negative integer"):
        OneshotPlanner(name="arrange-up", params={"semantics": "deterministic", "seed": -1})


def test_a_solve_timeout_that_is_not_a_positive_number_is_refused():
    problem = to_up(load("blocks-1"))
    for timeout in (-1, 0, float("nan"), "abc", True):
        with pytest.raises(ValueError, match="arrange-up: timeout must be a positive number"):
            _solve(problem, timeout=timeout)


def test_a_particle_plan_reports_its_validation():
    params = {"particles": 2, "seed": 0, "validate": 6}
    result = _solve(to_up(load("blocks-1")), params=params, timeout=60)
    assert result.status is Status.SOLVED_SATISFICING
    assert result.metrics["validation_rollouts"] == result.metrics["validation_run"] == "6"
    assert 0 <= int(result.metrics["validation_successes"]) <= 6
    assert int(result.metrics["validation_searches"]) >= 1
    assert any("validated on 6 fresh rollouts" in log.message for log in result.log_messages)
    unchecked = _solve(to_up(load("blocks-1")), params={**params, "validate": 0}, timeout=60)
    assert "validation_rollouts" not in unchecked.metrics


def test_registration_is_idempotent():
    registration.register()
    registration.register()
    factory = get_environment().factory
    assert factory.engines.count("arrange-up") == 1
    cls = ArrangeUpPlanner
    assert cls.supports(to_up(load("blocks-1")).kind)
    planner = cls()
    assert planner.name == "arrange-up"


ENGINE_CLASSES = {
    "arrange-up": ArrangeUpPlanner,
    "arrange-up-reliability": ArrangeUpReliability,
    "arrange-up-fixtures": ArrangeUpFixtureRepairer,
}


@pytest.mark.parametrize("name", sorted(ENGINE_CLASSES))
def test_every_engine_gives_credits_and_unified_planning_prints_them(name):
    credits = ENGINE_CLASSES[name].get_credits()
    assert credits.name == name and credits.license == "MIT"
    assert credits.author and credits.short_description and credits.long_description
    environment = get_environment()
    stream, saved = io.StringIO(), environment.credits_stream
    environment.credits_stream = stream
    try:
        factory = environment.factory
        operation = {
            "arrange-up": factory.OneshotPlanner,
            "arrange-up-reliability": factory.PlanValidator,
            "arrange-up-fixtures": factory.PlanRepairer,
        }[name]
        with operation(name=name):
            pass
    finally:
        environment.credits_stream = saved
    assert f"Engine name: {name}" in stream.getvalue()


@pytest.mark.parametrize("name", sorted(ENGINE_CLASSES))
def test_every_engine_supports_the_kinds_of_to_up_and_pddl_read_problems_only(name):
    cls = ENGINE_CLASSES[name]
    for domain in ("blocks-1", "tz-mating", "create-a-t"):  # with and without relative goals
        assert cls.supports(to_up(load(domain)).kind)
        pddl = PDDLReader().parse_problem(str(domain_path()), str(domains_dir() / f"{domain}.pddl"))
        assert cls.supports(pddl.kind)
        assert pddl.kind <= cls.supported_kind()
    # a plain classical problem (and the bare kind unified-planning's meta engines ask about)
    assert not cls.supports(ProblemKind({"ACTION_BASED"}))
    assert not cls.supports(ProblemKind(set(cls.supported_kind().features) | {"CONTINUOUS_TIME"}))


def test_selection_by_kind_never_picks_arrange_up_for_a_classical_problem():
    from unified_planning.exceptions import UPNoSuitableEngineAvailableException
    from unified_planning.test.examples import get_example_problems

    basic = get_example_problems()["basic"].problem  # one boolean fluent, one action
    environment = get_environment()
    saved, environment.credits_stream = environment.credits_stream, None
    try:
        with OneshotPlanner(problem_kind=basic.kind) as planner:
            chosen = planner.name  # another engine, if one is installed
    except UPNoSuitableEngineAvailableException:
        chosen = None
    finally:
        environment.credits_stream = saved
    assert chosen != "arrange-up"


def test_the_planner_and_the_repairer_are_satisficing_not_optimal():
    for cls in (ArrangeUpPlanner, ArrangeUpFixtureRepairer):
        assert cls.satisfies(OptimalityGuarantee.SATISFICING)
        assert not cls.satisfies(OptimalityGuarantee.SOLVED_OPTIMALLY)
    problem = to_up(load("blocks-1"))
    with OneshotPlanner(
        problem_kind=problem.kind, optimality_guarantee=OptimalityGuarantee.SATISFICING
    ) as planner:
        assert planner.name == "arrange-up"


@pytest.mark.parametrize(
    ("name", "typo", "meant"),
    [
        ("arrange-up", "particle", "particles"),
        ("arrange-up-reliability", "rollout", "rollouts"),
        ("arrange-up-fixtures", "methods", "method"),
    ],
)
def test_a_misspelt_parameter_is_named_with_the_accepted_ones(name, typo, meant):
    operation = {
        "arrange-up": OneshotPlanner,
        "arrange-up-reliability": PlanValidator,
        "arrange-up-fixtures": PlanRepairer,
    }[name]
    with pytest.raises(TypeError) as raised:
        operation(name=name, params={typo: 3})
    message = str(raised.value)
    assert f"{name}: unknown parameter {typo!r} (did you mean {meant!r}?)" in message
    for accepted in ENGINE_CLASSES[name]._PARAMETERS:
        assert accepted in message


# Each order runs in a fresh interpreter: the registration depends on what is imported first.
_IMPORT_ORDERS = {
    "arrange_up first": (
        "import sys\n"
        "import arrange_up\n"
        "assert 'unified_planning' not in sys.modules, 'import arrange_up imported UP'\n"
        "loaded = [m for m in sys.modules if m.startswith('arrange_up.up.')]\n"
        "assert loaded == ['arrange_up.up.registration'], loaded\n"
        "from unified_planning.shortcuts import OneshotPlanner, get_environment\n"
    ),
    "unified_planning first": (
        "from unified_planning.shortcuts import OneshotPlanner, get_environment\n"
        "import arrange_up\n"
    ),
    "unified_planning's environment first": (
        "from unified_planning.shortcuts import OneshotPlanner, get_environment\n"
        "get_environment()\n"
        "import arrange_up\n"
    ),
}
_SELECT_AND_SOLVE = """
import sys
from arrange_up.up.registration import _FactoryHook
assert not any(isinstance(f, _FactoryHook) for f in sys.meta_path), 'the hook outlived its use'
from arrange_up.io.domains import load
from arrange_up.up.compile import to_up
get_environment().credits_stream = None  # the engines' credits would precede the answers
factory = get_environment().factory
names = ('arrange-up', 'arrange-up-reliability', 'arrange-up-fixtures')
assert all(factory.engines.count(name) == 1 for name in names), factory.engines
problem = to_up(load('blocks-1'))
with OneshotPlanner(name='arrange-up', params={'semantics': 'deterministic'}) as planner:
    print(planner.name, type(planner).__module__, planner.solve(problem).status.name)
with OneshotPlanner(problem_kind=problem.kind) as planner:
    print(planner.name)
"""


@pytest.mark.parametrize("order", sorted(_IMPORT_ORDERS))
def test_the_engines_are_registered_in_either_import_order(order):
    done = subprocess.run(
        [sys.executable, "-c", _IMPORT_ORDERS[order] + _SELECT_AND_SOLVE],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=ROOT,
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.split("\n")[:2] == [
        "arrange-up arrange_up.up.planner_engine SOLVED_SATISFICING",
        "arrange-up",
    ]


def test_the_engine_classes_are_module_level_and_picklable():
    for name, module, class_name in registration.ENGINES:
        cls = getattr(importlib.import_module(module), class_name)
        assert (cls.__module__, cls.__qualname__) == (module, class_name)
        assert get_environment().factory.engines.count(name) == 1
        assert pickle.loads(pickle.dumps(cls)) is cls


def test_the_example_runs(capsys):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        module = runpy.run_path(str(ROOT / "examples" / "plan_with_unified_planning.py"))
        assert module["main"]("blocks-1") == 0
    out = capsys.readouterr().out
    assert "SOLVED_SATISFICING" in out and "validator: VALID" in out


def test_a_plan_solved_from_pddl_is_validated_against_the_file_as_arrange_up_loads_it():
    from arrange_up.io.pddl import load_pddl_problem
    from arrange_up.up.compile import plan_from_up, plan_to_up

    path = domains_dir() / "blocks-2.pddl"
    up = PDDLReader().parse_problem(str(domain_path()), str(path))
    result = _solve(up)
    assert {i.actual_parameters[0].object().name for i in result.plan.actions} <= {
        "a",
        "b",
        "paddle",
    }  # PDDLReader lowercases the file's A and B
    held = load_pddl_problem(path)  # the written case: A, B
    verdicts = []
    for target in (up, to_up(held)):
        with PlanValidator(name="arrange-up-reliability", params=ROLLOUTS) as validator:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # the reliability validator is chosen by name
                check = validator.validate(target, result.plan)
        assert check.status is not ValidationResultStatus.UNKNOWN, check.log_messages
        verdicts.append((check.status, check.metrics["successes"], check.metrics["trials"]))
    assert verdicts[0] == verdicts[1]  # the same problem, whichever case its names are in
    # the plan's actions, named as the held problem names its objects, for UP's own validator
    actions = plan_from_up(result.plan, held)
    assert {getattr(a, "obj", getattr(a, "manipulator", None)) for a in actions} <= {
        "A",
        "B",
        "paddle",
    }
    compiled = to_up(held)
    with PlanValidator(name="sequential_plan_validator") as validator:
        check = validator.validate(compiled, plan_to_up(compiled, actions))
    assert check.status is ValidationResultStatus.VALID


def test_an_exhausted_search_is_incomplete_and_a_too_large_part_proven_unsolvable():
    exhausted = _solve(
        to_up(tiny("obstacle")), {"semantics": "particles", "particles": 5, "seed": 0}
    )
    assert exhausted.status is Status.UNSOLVABLE_INCOMPLETELY and exhausted.plan is None
    assert exhausted.metrics["status"] == "exhausted"
    message = exhausted.log_messages[0].message
    assert message.startswith("exhausted after 3 nodes: ") and "not proven unsolvable" in message
    big, _ = check_problem_text(
        "name: big\ntable: {size: [3, 2]}\nobjects:\n  A: {kind: part, shape: {box: [4, 3]}}\n"
        "  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}\n"
        "goal: {tolerance: [0.2, 0.2, 15], poses: {A: [1.5, 1, 0]}}\n",
        "big",
    )
    assert big is not None
    proven = _solve(to_up(big))
    assert proven.status is Status.UNSOLVABLE_PROVEN and proven.plan is None
    assert proven.log_messages[0].message == (
        "part A (4 x 3 in) fits the 3 x 2 in table at no angle: no plan exists"
    )


def test_the_planner_engine_runs_its_successors_where_told_with_the_same_plan():
    problem = to_up(load("blocks-2"))
    params = {"particles": 5, "seed": 0}
    here = _solve(problem, {**params, "workers": 1})
    pooled = _solve(problem, {**params, "workers": 2, "backend": "local"})
    assert here.status is Status.SOLVED_SATISFICING
    assert str(pooled.plan) == str(here.plan)
    with pytest.raises(ValueError, match="backend must be"):
        OneshotPlanner(name="arrange-up", params={"backend": "ray"})
    with pytest.raises(ValueError, match="scheduler address needs"):
        OneshotPlanner(name="arrange-up", params={"scheduler": "tcp://127.0.0.1:1"})


def test_a_problem_read_by_pddlreader_has_lowercase_names_and_the_same_nominal_plan():
    # docs/tutorial.md: unified-planning's reader lowercases names; a deterministic plan (no
    # noise drawn from the names) is the command line's, up to their case
    path = domains_dir() / "blocks-2.pddl"
    read = PDDLReader().parse_problem(str(domain_path()), str(path))
    assert {spec.name for spec in load("blocks-2").objects} >= {"A", "B"}
    assert {spec.name for spec in from_up(read).objects} >= {"a", "b", "paddle"}
    from_pddl = _solve(read)
    from_yaml = _solve(to_up(load("blocks-2")))
    assert from_pddl.status is from_yaml.status is Status.SOLVED_SATISFICING
    assert str(from_pddl.plan).lower() == str(from_yaml.plan).lower()


def _pddl_read(name):
    return PDDLReader().parse_problem(str(domain_path()), str(domains_dir() / f"{name}.pddl"))


@pytest.mark.parametrize("name", ["blocks-2", "tz-mating"])  # absolute and relative goals
def test_a_problem_read_by_up_from_pddl_finds_arrange_up_by_kind_and_validates(name):
    problem = _pddl_read(name)
    environment = get_environment()
    saved, environment.credits_stream = environment.credits_stream, None
    try:
        with OneshotPlanner(problem_kind=problem.kind) as planner:
            assert planner.name == "arrange-up"
    finally:
        environment.credits_stream = saved
    result = _solve(problem, timeout=120)
    assert result.status is Status.SOLVED_SATISFICING
    # the plan's actions are the problem's own, so unified-planning's simulator accepts them
    assert all(instance.action in problem.actions for instance in result.plan.actions)
    assert any(len(i.actual_parameters) > 1 for i in result.plan.actions)  # poses carried
    with PlanValidator(name="sequential_plan_validator") as validator:
        check = validator.validate(problem, result.plan)
    assert check.status is ValidationResultStatus.VALID, check
    # equipped once: solving again maps it back through its effects, same plan
    assert str(_solve(problem, timeout=120).plan) == str(result.plan)


def test_replanner_is_refused_with_a_message_saying_so():
    from unified_planning.shortcuts import Replanner

    problem = to_up(load("blocks-1"))
    environment = get_environment()
    saved, environment.credits_stream = environment.credits_stream, None
    try:
        with pytest.raises(TypeError, match="not a replanner.*meta"):
            Replanner(problem, name="arrange-up")
    finally:
        environment.credits_stream = saved
    assert not any(name.endswith("[arrange-up]") for name in environment.factory.engines)
