"""The landing rule: a paddle put down onto a part fails the push (``fail``, the default) or
is resolved by the physics (``shove``)."""

from __future__ import annotations

import math

import pytest

from arrange_up.evaluation.evaluate import evaluate_plan
from arrange_up.evaluation.records import RecordFileError
from arrange_up.evaluation.rollouts import PUSH_OVERLAP_REASON
from arrange_up.io.domains import load
from arrange_up.model.world import Place, Push
from arrange_up.parallel import SERIAL

EAST = -math.pi / 2.0  # the paddle pushes along +x
# The paddle (0.15 in thick) put down 0.2 in inside block A's left face.
PLAN = [Place("A", (5.0, 2.5, 0.0)), Push("paddle", (4.7, 2.5, EAST), 1.0)]


def test_fail_is_the_default_and_names_the_landing():
    problem = load("blocks-1")
    result = evaluate_plan(problem, PLAN, rollouts=2, runner=SERIAL)
    assert result == evaluate_plan(problem, PLAN, rollouts=2, runner=SERIAL, landing="fail")
    (failure,) = result.failures.action_failures
    assert (failure.action, failure.rollouts) == (1, 2)
    assert failure.reason.startswith(PUSH_OVERLAP_REASON)
    assert "landing" not in result.to_json()


def test_shove_lets_the_physics_resolve_it():
    problem = load("blocks-1")
    result = evaluate_plan(problem, PLAN, rollouts=2, runner=SERIAL, landing="shove")
    assert result.failures.action_failed == 0
    assert result.to_json()["landing"] == "shove"


def test_landing_is_checked_and_part_of_the_record(tmp_path):
    problem = load("blocks-1")
    with pytest.raises(ValueError, match="unknown landing 'skip'"):
        evaluate_plan(problem, PLAN, rollouts=1, runner=SERIAL, landing="skip")
    record = tmp_path / "r.jsonl"
    evaluate_plan(problem, PLAN, rollouts=1, runner=SERIAL, record=record)
    with pytest.raises(RecordFileError):
        evaluate_plan(problem, PLAN, rollouts=1, runner=SERIAL, record=record, landing="shove")


def test_cli_landing_option(tmp_path):
    from click.testing import CliRunner

    from arrange_up.cli import main
    from arrange_up.io.planfile import plan_document, write_json_atomic

    problem = load("blocks-1")
    path = tmp_path / "landing.json"
    doc = plan_document(
        problem, PLAN, status="solved", semantics="deterministic", seed=0, search={}
    )
    write_json_atomic(path, doc)
    args = ["evaluate", "blocks-1", str(path), "--rollouts", "2", "--workers", "1"]
    failing = CliRunner().invoke(main, args)
    assert failing.exit_code == 0, failing.output
    assert PUSH_OVERLAP_REASON in failing.stdout
    shoving = CliRunner().invoke(main, [*args, "--landing", "shove", "--json"])
    assert shoving.exit_code == 0, shoving.output
    assert '"landing": "shove"' in shoving.stdout
    bad = CliRunner().invoke(main, [*args, "--landing", "skip"])
    assert bad.exit_code == 2
