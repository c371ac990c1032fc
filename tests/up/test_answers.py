"""The engines answer every question with an honest status, never an exception (issue 14): the
repairer's plans reach the goal, every problem unified-planning can build gets a status,
timeouts are honoured, and unified-planning's ``up`` command can find the engines."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import warnings
from dataclasses import replace
from pathlib import Path

import pytest
from unified_planning.engines import PlanGenerationResultStatus as Status
from unified_planning.engines.results import FailedValidationReason, ValidationResultStatus
from unified_planning.environment import get_environment
from unified_planning.plans import SequentialPlan
from unified_planning.shortcuts import OneshotPlanner, PlanRepairer, PlanValidator
from unified_planning.test.examples import get_example_problems

import arrange_up.up.engine_io as engine_io
import arrange_up.up.repairer_engine as repairer_engine
from arrange_up.io.domains import domains_dir, load
from arrange_up.io.pddl import domain_path
from arrange_up.planning.planner import plan
from arrange_up.repair import repair_plan
from arrange_up.up.compile import plan_from_up, plan_to_up, to_up
from arrange_up.up.registration import register

register()
ROOT = Path(__file__).resolve().parents[2]
FAST_REPAIR = {"particles": 4, "seed": 1}


@pytest.fixture(autouse=True)
def _no_credit_banners():
    environment = get_environment()
    saved, environment.credits_stream = environment.credits_stream, None
    yield
    environment.credits_stream = saved


@pytest.fixture(scope="module")
def blocks1():
    problem = load("blocks-1")
    nominal = plan(problem, semantics="deterministic", seed=0)
    assert nominal.status == "solved"
    return problem, to_up(problem), nominal.actions


def _repair(up_problem, up_plan, params=FAST_REPAIR):
    with PlanRepairer(name="arrange-up-fixtures", params=params) as repairer:
        return repairer.repair(up_problem, up_plan)


def _ups_verdict(up_problem, up_plan):
    with PlanValidator(name="sequential_plan_validator") as validator:
        return validator.validate(up_problem, up_plan)


# -- item 1: the repairer's plans reach the goal ---------------------------------------------
def test_a_repaired_plan_reaches_the_goal_by_ups_own_validator(blocks1):
    _, up_problem, nominal = blocks1
    result = _repair(up_problem, plan_to_up(up_problem, nominal))
    assert result.status is Status.SOLVED_SATISFICING
    assert _ups_verdict(up_problem, result.plan).status is ValidationResultStatus.VALID


@pytest.mark.parametrize("cut", ["empty", "without its last push"])
def test_a_plan_that_misses_the_goal_is_not_repaired_into_a_success(blocks1, cut):
    _, up_problem, nominal = blocks1
    actions = () if cut == "empty" else nominal[:-1]
    given = plan_to_up(up_problem, actions)
    check = _ups_verdict(up_problem, given)
    assert check.status is ValidationResultStatus.INVALID
    assert check.reason is FailedValidationReason.UNSATISFIED_GOALS
    result = _repair(up_problem, given)
    assert result.status is Status.UNSOLVABLE_INCOMPLETELY
    assert result.plan is None
    message = result.log_messages[0].message
    assert "not a nominal plan" in message and "the goal is not reached: A " in message
    assert "does not complete plans" in message


def test_an_inapplicable_plan_is_an_honest_failure(blocks1):
    _, up_problem, nominal = blocks1
    twice = plan_to_up(up_problem, (nominal[0], *nominal))  # places A twice
    result = _repair(up_problem, twice)
    assert result.status is Status.UNSOLVABLE_INCOMPLETELY
    assert "action 2 (place A) places A, which is already on the table" in (
        result.log_messages[0].message
    )


def test_a_repair_that_misses_the_goal_nominally_is_not_returned(blocks1, monkeypatch):
    problem, up_problem, nominal = blocks1
    real = repair_plan

    def short_of_the_goal(*args, **kwargs):  # a repair whose plan lost its last push
        outcome = real(*args, **kwargs)
        return replace(outcome, actions=outcome.actions[:-1])

    monkeypatch.setattr(repairer_engine, "repair_plan", short_of_the_goal)
    result = _repair(up_problem, plan_to_up(up_problem, nominal))
    assert result.status is Status.UNSOLVABLE_INCOMPLETELY
    assert result.plan is None and result.metrics["status"] == "missed-goal"
    assert "does not reach the goal in the deterministic semantics" in (
        result.log_messages[0].message
    )


# -- item 2: timeouts ------------------------------------------------------------------------
def test_the_repairer_honours_its_timeout(blocks1):
    _, up_problem, nominal = blocks1
    result = _repair(up_problem, plan_to_up(up_problem, nominal), {**FAST_REPAIR, "timeout": 1e-9})
    assert result.status is Status.TIMEOUT
    assert result.plan is None and "timeout of 1e-09 s" in result.log_messages[0].message


def test_the_validator_honours_its_timeout(blocks1):
    _, up_problem, nominal = blocks1
    params = {"rollouts": 100000, "workers": 1, "timeout": 0.2}
    with PlanValidator(name="arrange-up-reliability", params=params) as validator:
        check = validator.validate(up_problem, plan_to_up(up_problem, nominal))
    assert check.status is ValidationResultStatus.UNKNOWN
    assert "timeout of 0.2 s reached after" in check.log_messages[0].message
    assert 0 <= int(check.metrics["done"]) < 100000


@pytest.mark.parametrize("name", ["arrange-up-reliability", "arrange-up-fixtures"])
def test_a_bad_timeout_is_refused(name):
    operation = PlanValidator if name == "arrange-up-reliability" else PlanRepairer
    with pytest.raises(ValueError, match="timeout must be a positive number of seconds"):
        operation(name=name, params={"timeout": 0})


# -- item 2: every problem unified-planning can build gets a status ------------------------
_ANSWERS = {
    "arrange-up": {Status.UNSUPPORTED_PROBLEM},
    "arrange-up-reliability": {ValidationResultStatus.UNKNOWN},
    "arrange-up-fixtures": {Status.UNSUPPORTED_PROBLEM},
}


def _example_plan(case):
    plans = [*case.valid_plans, *case.invalid_plans]
    return plans[0] if plans else SequentialPlan([])


def test_every_example_problem_of_unified_planning_gets_a_status_from_every_engine():
    """Loops over ``unified_planning.test.examples.get_example_problems()`` (66 problems in
    unified-planning 1.3.0) with each engine: none is an arrange-up problem, so each must be
    refused with a status and a log message saying why, never with an exception."""
    answered = {name: 0 for name in _ANSWERS}
    examples = get_example_problems()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "We cannot establish whether ..." for each
        with (
            OneshotPlanner(name="arrange-up", params={"particles": 2}) as planner,
            PlanValidator(
                name="arrange-up-reliability", params={"rollouts": 2, "workers": 1}
            ) as validator,
            PlanRepairer(name="arrange-up-fixtures", params={"particles": 2}) as repairer,
        ):
            for case_name, case in sorted(examples.items()):
                problem, example_plan = case.problem, _example_plan(case)
                results = {  # an engine that raises fails the test here
                    "arrange-up": planner.solve(problem, timeout=5),
                    "arrange-up-reliability": validator.validate(problem, example_plan),
                    "arrange-up-fixtures": repairer.repair(problem, example_plan),
                }
                for name, result in results.items():
                    assert result.status in _ANSWERS[name], (case_name, name, result)
                    assert result.log_messages and result.log_messages[0].message
                    answered[name] += 1
    assert answered == {name: len(examples) for name in _ANSWERS}


def test_an_unreadable_problem_is_reported_not_raised(monkeypatch):
    def broken(problem):
        raise TypeError("a reader defect")

    monkeypatch.setattr(engine_io, "from_up", broken)
    with OneshotPlanner(name="arrange-up") as planner:
        result = planner.solve(to_up(load("blocks-1")))
    assert result.status is Status.INTERNAL_ERROR
    assert result.log_messages[0].message == (
        "reading the problem failed: TypeError: a reader defect"
    )


def test_a_plan_of_another_kind_is_refused_with_a_status(blocks1):
    from unified_planning.plans import TimeTriggeredPlan

    _, up_problem, _ = blocks1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "cannot validate this kind of plan"
        result = _repair(up_problem, TimeTriggeredPlan([]))
    assert result.status is Status.UNSUPPORTED_PROBLEM
    assert "a TimeTriggeredPlan is not a sequential plan" in result.log_messages[0].message
    with pytest.raises(ValueError, match="not a sequential plan"):
        plan_from_up(TimeTriggeredPlan([]))


# -- item 5: unified-planning's up command finds the engines -------------------------------
def test_the_up_command_finds_the_engines_through_the_printed_configuration(tmp_path):
    up_command = Path(sys.executable).with_name("up")
    if not up_command.exists():
        pytest.skip("unified-planning's up command is not installed beside this Python")
    env = {**os.environ, "PYTHONPATH": str(ROOT), "HOME": str(tmp_path)}
    printed = subprocess.run(
        [sys.executable, "-m", "arrange_up.up"],
        capture_output=True,
        text=True,
        env=env,
        check=True,
        timeout=60,
    )
    (tmp_path / ".up.ini").write_text(printed.stdout, encoding="utf-8")
    command = [str(up_command), "oneshot-planning", "--engine", "arrange-up", "--pddl"]
    command += [str(domain_path()), str(domains_dir() / "blocks-1.pddl")]
    command += ["--plan", str(tmp_path / "blocks-1.plan")]
    done = subprocess.run(
        command, capture_output=True, text=True, env=env, timeout=300, cwd=tmp_path
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "Status returned by arrange-up: SOLVED_SATISFICING" in done.stdout
    # --plan: unified-planning's PDDL writer, taught real parameters (arrange_up.up.plan_writer)
    written = (tmp_path / "blocks-1.plan").read_text(encoding="utf-8").splitlines()
    assert written[0].startswith("(place a 9.088 0.912 ")
    assert all(re.fullmatch(r"\((place|push|pick) [a-z]+( -?\d+(\.\d+)?)*\)", w) for w in written)
    listed = subprocess.run(
        [str(up_command), "list-engines"], capture_output=True, text=True, env=env, timeout=120
    )
    for name in ("arrange-up", "arrange-up-reliability", "arrange-up-fixtures"):
        assert f"Engine's factory name: {name}\n" in listed.stdout


def test_installing_the_configuration_is_idempotent(tmp_path):
    from arrange_up.up.__main__ import install
    from arrange_up.up.registration import up_ini

    path = tmp_path / "up.ini"
    path.write_text("[engine other]\nmodule_name: m\nclass_name: C\n", encoding="utf-8")
    assert install(path) is True
    assert install(path) is False
    text = path.read_text(encoding="utf-8")
    assert text.startswith("[engine other]") and text.endswith(up_ini())
    assert text.count("[engine arrange-up]") == 1


def test_installing_over_sections_naming_another_module_says_what_to_edit(tmp_path):
    from arrange_up.up.__main__ import install
    from arrange_up.up.registration import up_ini

    path = tmp_path / "up.ini"
    moved = up_ini().replace("arrange_up.up.validator_engine", "arrange_up.up.engines")
    path.write_text(moved, encoding="utf-8")
    with pytest.raises(SystemExit, match="names arrange-up-reliability with another module"):
        install(path)
    assert path.read_text(encoding="utf-8") == moved
