"""Tests of arrange_up.evaluation.evaluate (rollouts, failures, records, resume), its CLI command
and the
``arrange-up-reliability`` validator engine."""

from __future__ import annotations

import json
import math
import sys
from dataclasses import replace

import numpy as np
import pytest
from click.testing import CliRunner

from arrange_up.cli import main
from arrange_up.evaluation.evaluate import evaluate_plan
from arrange_up.evaluation.outcomes import (
    ACTION_FAILED,
    GOAL_MISSED,
    NOT_AT_REST,
    OFF_TABLE,
    RolloutRecord,
)
from arrange_up.evaluation.records import RecordFile as _RecordFile
from arrange_up.evaluation.records import RecordFileError, plan_hash
from arrange_up.evaluation.reliability import EvaluationProgress, wilson_interval
from arrange_up.evaluation.rollouts import execute_plan, simulate_rollout, trace_rollout
from arrange_up.io.domains import load
from arrange_up.io.planfile import plan_document, write_json_atomic
from arrange_up.io.yaml_problem import load_problem_text
from arrange_up.model.problem import (
    ArrangementProblem,
    Goal,
    ObjectKind,
    ObjectSpec,
    Shape,
    Table,
    Uncertainty,
)
from arrange_up.model.world import Pick, Place, Push, WorldState
from arrange_up.parallel import SERIAL, RunnerConfig
from arrange_up.planning.planner import plan

EAST = -math.pi / 2  # paddle theta that pushes toward +x


@pytest.fixture(scope="module")
def blocks2():
    problem = load("blocks-2")
    result = plan(problem, semantics="deterministic", seed=0)
    assert result.solved
    return problem, result.actions


@pytest.fixture(scope="module")
def blocks1():
    problem = load("blocks-1")
    result = plan(problem, semantics="deterministic", seed=0)
    assert result.solved
    return problem, result.actions


def _box(width: float, height: float) -> Shape:
    w, h = width / 2, height / 2
    return Shape(parts=(((-w, -h), (w, -h), (w, h), (-w, h)),), box=(width, height))


def _open_right() -> ArrangementProblem:
    """One block and a paddle on a noise-free table whose right edge has no wall."""
    return ArrangementProblem(
        name="open-right",
        table=Table((10.0, 5.0), walls=("left", "bottom", "top")),
        objects=(
            ObjectSpec("A", ObjectKind.PART, _box(1.0, 1.0)),
            ObjectSpec("B", ObjectKind.PART, _box(1.0, 1.0)),
            ObjectSpec("paddle", ObjectKind.MANIPULATOR, _box(2.5, 0.15)),
        ),
        initial=(),
        goal=Goal(targets=(("A", (9.0, 2.5, 0.0)),), tolerance=(0.1, 0.1, 0.1)),
    )


# -- statistics --------------------------------------------------------------------------------
def test_wilson_interval_known_values():
    low, high = wilson_interval(0, 10)
    assert low == 0.0 and high == pytest.approx(0.27753, abs=1e-5)
    low, high = wilson_interval(10, 10)
    assert high == 1.0 and low == pytest.approx(0.72247, abs=1e-5)
    low, high = wilson_interval(50, 100)
    assert (low, high) == pytest.approx((0.40383, 0.59617), abs=1e-5)
    assert wilson_interval(0, 0) == (0.0, 1.0)
    with pytest.raises(ValueError):
        wilson_interval(3, 2)


# -- rollouts -----------------------------------------------------------------------------------
def test_results_do_not_depend_on_workers_or_chunks(blocks2):
    problem, actions = blocks2
    serial = evaluate_plan(problem, actions, rollouts=24, seed=3, runner=SERIAL, keep_records=True)
    assert serial.trials == 24 and 0 < serial.successes < 24
    assert serial.rate == serial.successes / 24
    assert serial.interval == wilson_interval(serial.successes, 24)
    pooled = evaluate_plan(
        problem,
        actions,
        rollouts=24,
        seed=3,
        runner=RunnerConfig(workers=2),
        chunksize=5,
        keep_records=True,
    )
    assert pooled == serial and pooled.workers == 2
    assert [r.index for r in serial.records] == list(range(24))
    assert simulate_rollout(problem, actions, 3, 7) == serial.records[7]
    for record in serial.records[:6]:
        states = trace_rollout(problem, actions, 3, record.index)
        failed_at = None if record.success else record.failure.action
        assert len(states) == (len(actions) + 1 if failed_at is None else failed_at + 1)
        assert states[0].names() == ()  # blocks-2 starts with nothing on the table
    other = evaluate_plan(problem, actions, rollouts=24, seed=4, runner=SERIAL)
    assert other != serial  # another seed draws other worlds


def test_a_missed_goal_names_parts_and_dimensions():
    problem = load("blocks-1")
    result = evaluate_plan(problem, [Place("A", (5.0, 2.5, 0.0))], rollouts=5, runner=SERIAL)
    assert result.successes == 0 and result.failures.goal_missed == 5
    dims = {(m.part, m.dimension): m for m in result.failures.goal_misses}
    assert set(dims) == {("A", "x"), ("A", "y")}
    assert dims[("A", "x")].rollouts == 5 and dims[("A", "x")].worst > 3.5
    empty = evaluate_plan(problem, [], rollouts=2, runner=SERIAL)
    assert [(m.part, m.dimension) for m in empty.failures.goal_misses] == [("A", "off table")]


def test_inapplicable_actions_are_recorded_with_their_index_and_reason():
    problem = load("blocks-2")
    twice = [Place("A", (5.0, 2.5, 0.0)), Place("A", (3.0, 2.5, 0.0))]
    result = evaluate_plan(problem, twice, rollouts=3, runner=SERIAL)
    (failure,) = result.failures.action_failures
    assert (failure.action, failure.rollouts) == (1, 3)
    assert "already on the table" in failure.reason
    picked = evaluate_plan(problem, [Pick("B")], rollouts=1, runner=SERIAL)
    assert picked.failures.action_failed == 1
    stacked = [Place("A", (5.0, 2.5, 0.0)), Place("B", (5.3, 2.5, 0.0))]
    result = evaluate_plan(problem, stacked, rollouts=2, runner=SERIAL, keep_records=True)
    assert result.failures.action_failures[0].reason.startswith("placed overlapping A")
    assert result.records[0].failure.detail.startswith("overlap 0.")


#: Two 5 cm blocks and a paddle, written in centimetres.
CM_PAIR = """
name: cm-pair
units: {length: cm}
table: {size: [50, 30]}
objects:
  A: {kind: part, shape: {box: [5, 5]}}
  B: {kind: part, shape: {box: [5, 5]}}
  paddle: {kind: manipulator, shape: {box: [6.35, 0.38]}}
goal: {tolerance: [0.5, 0.5], poses: {A: [10, 10, 0], B: [20, 10, 0]}}
"""


def test_an_overlap_is_reported_in_the_files_length_unit():
    problem = load_problem_text(CM_PAIR, "cm-pair.yaml")
    # B put down 1 cm into A; the paddle put down across A's lower edge (actions are in
    # inches)
    a, b = (10 / 2.54, 10 / 2.54, 0.0), (14 / 2.54, 10 / 2.54, 0.0)
    stacked = [Place("A", a), Place("B", b)]
    result = evaluate_plan(problem, stacked, rollouts=1, runner=SERIAL, keep_records=True)
    assert result.failures.action_failures[0].reason == (
        "placed overlapping A (by more than 0.0508 cm)"
    )
    assert result.records[0].failure.detail.endswith(" cm")
    landed = [Place("A", a), Push("paddle", (a[0], 8 / 2.54, 0.0), 1.0)]  # 0.5 cm into A
    result = evaluate_plan(problem, landed, rollouts=1, runner=SERIAL, keep_records=True)
    assert result.failures.action_failures[0].reason == (
        "the push started with shapes overlapping (by more than 0.0508 cm)"
    )
    assert result.records[0].failure.detail.endswith(" cm")


def test_off_table_and_not_at_rest_are_told_apart(monkeypatch):
    problem = _open_right()
    push_off = [Place("A", (8.0, 2.5, 0.0)), Push("paddle", (7.325, 2.5, EAST), 3.0)]
    result = evaluate_plan(problem, push_off, rollouts=1, runner=SERIAL, keep_records=True)
    assert result.failures.off_table == 1
    assert result.failures.off_table_actions[0][:2] == (1, "A")
    assert result.records[0].failure.kind == OFF_TABLE

    import arrange_up.physics.simulation as physics

    real = physics.simulate

    def capped(problem, state, action, noise=None, settings=physics.DEFAULT_SETTINGS):
        outcome = real(problem, state, action, noise, settings)
        if isinstance(action, Push):
            return replace(outcome, status=physics.SimulationStatus.NOT_AT_REST)
        return outcome

    monkeypatch.setattr(physics, "simulate", capped)
    result = evaluate_plan(problem, push_off, rollouts=2, runner=SERIAL)
    assert result.failures.not_at_rest == 2
    assert result.failures.not_at_rest_actions[0] == (1, 2)


def test_execution_draws_noise_and_stops_at_the_first_failure():
    problem = replace(
        _open_right(),
        uncertainty=Uncertainty(
            place=(0.02, 0.02, 0.01), push=(0.01, 0.01, 0.005), friction=(0.3, 0.5)
        ),
    )
    state = WorldState.from_mapping(problem, {"B": (2.0, 1.0, 0.0)})
    actions = [
        Place("A", (8.0, 2.5, 0.0)),
        Push("paddle", (7.325, 2.5, EAST), 3.0),  # off the open right edge
        Pick("B"),
    ]
    run = execute_plan(problem, state, actions, np.random.default_rng(3))
    assert not run.ok and run.failure.kind == OFF_TABLE and run.failure.action == 1
    assert len(run.states) == 2 and run.states[0] == state
    assert run.state.pose("A") != (8.0, 2.5, 0.0)  # noise was drawn
    again = execute_plan(problem, state, actions, np.random.default_rng(3))
    assert again == run
    fine = execute_plan(problem, state, [actions[0], Pick("B")], np.random.default_rng(3))
    assert fine.ok and fine.state.names() == ("A",)
    assert fine.states[1] == run.states[1]


def test_bad_arguments_are_refused(blocks1):
    problem, actions = blocks1
    with pytest.raises(ValueError, match="rollouts"):
        evaluate_plan(problem, actions, rollouts=0)
    with pytest.raises(ValueError, match="seed"):
        evaluate_plan(problem, actions, seed=-1)
    with pytest.raises(ValueError, match="backend"):
        evaluate_plan(problem, actions, runner=RunnerConfig(backend="cloud"))
    with pytest.raises(ValueError, match="no object 'Z'"):
        evaluate_plan(problem, [Place("Z", (1.0, 1.0, 0.0))], rollouts=1)


# -- records and resume --------------------------------------------------------------------------
def _lines(path):
    return path.read_text().splitlines()


def test_an_interrupted_run_resumes_to_the_identical_result(blocks2, tmp_path):
    problem, actions = blocks2
    record = tmp_path / "b2.jsonl"
    seen: list[EvaluationProgress] = []

    def stop_after_7(state: EvaluationProgress) -> None:
        seen.append(state)
        if state.done == 7:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        evaluate_plan(
            problem,
            actions,
            rollouts=30,
            seed=1,
            runner=SERIAL,
            record=record,
            progress=stop_after_7,
        )
    lines = _lines(record)
    header = json.loads(lines[0])
    assert header["seed"] == 1 and header["plan"]["hash"] == plan_hash(actions)
    assert [json.loads(line)["rollout"] for line in lines[1:]] == list(range(7))
    assert seen[0].done == 0 and seen[-1].done == 7

    resumed = evaluate_plan(
        problem, actions, rollouts=30, seed=1, runner=RunnerConfig(workers=2), record=record
    )
    assert resumed.resumed == 7
    straight = evaluate_plan(problem, actions, rollouts=30, seed=1, runner=SERIAL)
    assert resumed == straight
    assert len(_lines(record)) == 31
    again = evaluate_plan(problem, actions, rollouts=30, seed=1, runner=SERIAL, record=record)
    assert again == straight and again.resumed == 30 and len(_lines(record)) == 31


def test_an_interrupted_pool_run_keeps_its_records(blocks2, tmp_path):
    problem, actions = blocks2
    record = tmp_path / "pool.jsonl"

    def stop_after_9(state: EvaluationProgress) -> None:
        if state.done >= 9:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        evaluate_plan(
            problem,
            actions,
            rollouts=40,
            seed=2,
            runner=RunnerConfig(workers=2),
            chunksize=3,
            record=record,
            progress=stop_after_9,
        )
    assert len(_lines(record)) - 1 >= 9
    resumed = evaluate_plan(
        problem, actions, rollouts=40, seed=2, runner=RunnerConfig(workers=2), record=record
    )
    assert resumed.resumed >= 9
    assert resumed == evaluate_plan(problem, actions, rollouts=40, seed=2, runner=SERIAL)


def test_a_killed_process_loses_nothing_recorded(blocks1, tmp_path):
    import subprocess

    problem, actions = blocks1
    record = tmp_path / "killed.jsonl"
    code = (
        "import os, signal\n"
        "from arrange_up.io.domains import load\n"
        "from arrange_up.evaluation.evaluate import evaluate_plan\n"
        "from arrange_up.parallel import SERIAL\n"
        "from arrange_up.planning.planner import plan\n"
        "p = load('blocks-1')\n"
        "a = plan(p, semantics='deterministic', seed=0).actions\n"
        "def kill(s):\n"
        "    if s.done == 5:\n"
        "        os.kill(os.getpid(), signal.SIGKILL)\n"
        f"evaluate_plan(p, a, rollouts=12, runner=SERIAL, record={str(record)!r}, progress=kill)\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=120)
    assert done.returncode == -9, done.stderr
    assert len(_lines(record)) == 6
    resumed = evaluate_plan(problem, actions, rollouts=12, runner=SERIAL, record=record)
    assert resumed.resumed == 5
    assert resumed == evaluate_plan(problem, actions, rollouts=12, runner=SERIAL)


def test_a_record_can_be_extended_and_a_cut_line_is_dropped(blocks1, tmp_path):
    problem, actions = blocks1
    record = tmp_path / "b1.jsonl"
    evaluate_plan(problem, actions, rollouts=6, runner=SERIAL, record=record)
    text = record.read_text()
    record.write_text(text + '{"rollout": 6, "succ')  # killed while writing a line
    longer = evaluate_plan(problem, actions, rollouts=10, runner=SERIAL, record=record)
    assert longer.resumed == 6
    assert longer == evaluate_plan(problem, actions, rollouts=10, runner=SERIAL)
    lines = _lines(record)
    assert len(lines) == 11 and all(json.loads(line) for line in lines)
    shorter = evaluate_plan(problem, actions, rollouts=4, runner=SERIAL, record=record)
    assert shorter == evaluate_plan(problem, actions, rollouts=4, runner=SERIAL)


def test_a_record_of_another_evaluation_is_refused(blocks1, tmp_path):
    problem, actions = blocks1
    record = tmp_path / "r.jsonl"
    evaluate_plan(problem, actions, rollouts=2, seed=0, runner=SERIAL, record=record)
    with pytest.raises(RecordFileError, match="seed: file 0, this run 1"):
        evaluate_plan(problem, actions, rollouts=2, seed=1, runner=SERIAL, record=record)
    with pytest.raises(RecordFileError, match="plan.hash"):
        evaluate_plan(problem, actions[:-1], rollouts=2, seed=0, runner=SERIAL, record=record)
    other = tmp_path / "other.jsonl"
    other.write_text('{"format": "something-else"}\n')
    with pytest.raises(RecordFileError, match="not an arrange-up rollout record"):
        evaluate_plan(problem, actions, rollouts=2, runner=SERIAL, record=other)
    lines = _lines(record)
    record.write_text("\n".join([lines[0], "{oops", *lines[1:]]) + "\n")
    with pytest.raises(RecordFileError, match=r"r\.jsonl:2: not a rollout record"):
        evaluate_plan(problem, actions, rollouts=2, runner=SERIAL, record=record)


def test_a_file_that_is_not_a_record_is_refused_untouched_even_without_a_final_newline(
    blocks1, tmp_path
):
    # A file without a final newline looks like a record whose last line a kill cut off;
    # that line is dropped only once the file's header shows it is a record of this kind.
    problem, actions = blocks1
    for name, text in (
        ("plan.json", '{"format":"arrange-up-plan/1","actions":[]}'),  # one line, no newline
        ("notes.txt", "first line\nsecond line"),
        ("garbage.json", "not json at all"),
    ):
        path = tmp_path / name
        path.write_text(text)
        with pytest.raises(RecordFileError, match="not an arrange-up rollout record"):
            evaluate_plan(problem, actions, rollouts=2, runner=SERIAL, record=path)
        assert path.read_text() == text
    # the start of a header a kill cut off is a record begun: it starts afresh
    begun = tmp_path / "begun.jsonl"
    begun.write_text('{"format":"arrange-up-rol')
    result = evaluate_plan(problem, actions, rollouts=2, runner=SERIAL, record=begun)
    assert result == evaluate_plan(problem, actions, rollouts=2, runner=SERIAL)
    assert len(_lines(begun)) == 3


def test_a_record_in_use_is_refused(blocks1, tmp_path):
    problem, actions = blocks1
    record = tmp_path / "busy.jsonl"
    holder = _RecordFile(record, {"format": "arrange-up-rollouts/1"})
    try:
        with pytest.raises(RecordFileError, match="in use"):
            evaluate_plan(problem, actions, rollouts=1, runner=SERIAL, record=record)
    finally:
        holder.close()


def test_records_round_trip_through_json(blocks2):
    problem, actions = blocks2
    result = evaluate_plan(problem, actions, rollouts=8, runner=SERIAL, keep_records=True)
    for record in result.records:
        assert RolloutRecord.from_json(json.loads(json.dumps(record.to_json()))) == record
    kinds = {r.failure.kind for r in result.records if r.failure}
    assert kinds <= {GOAL_MISSED, ACTION_FAILED, NOT_AT_REST, OFF_TABLE}


# -- the command ---------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def plan_file(blocks1, tmp_path_factory):
    problem, actions = blocks1
    path = tmp_path_factory.mktemp("plans") / "b1.json"
    doc = plan_document(
        problem, actions, status="solved", semantics="deterministic", seed=0, search={}
    )
    write_json_atomic(path, doc)
    return path


def test_cli_json_summary(plan_file, tmp_path):
    record = tmp_path / "cli.jsonl"
    args = ["evaluate", "blocks-1", str(plan_file), "--rollouts", "12", "--workers", "1"]
    done = CliRunner().invoke(main, [*args, "--json", "--record", str(record)])
    assert done.exit_code == 0, done.output
    summary = json.loads(done.stdout)
    for key in ("successes", "trials", "rate", "interval", "failures", "seed", "rollouts"):
        assert key in summary
    for key in ("backend", "workers", "elapsed", "problem", "plan"):
        assert key in summary
    assert summary["trials"] == 12 and len(summary["interval"]) == 2
    assert summary["backend"] == "local" and summary["workers"] == 1
    assert summary["problem"]["name"] == "blocks-1"
    assert len(_lines(record)) == 13
    text = CliRunner().invoke(main, args)
    assert text.exit_code == 0
    assert "of 12 rollouts reached the goal" in text.stdout
    assert "95% Wilson interval" in text.stdout
    if summary["successes"] < 12:
        assert "action 2 (push paddle)" in text.stdout or "action 3" in text.stdout


def test_cli_bad_input_exits_2_cleanly(plan_file, tmp_path):
    runner = CliRunner()
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    done = runner.invoke(main, ["evaluate", "blocks-1", str(bad)])
    assert done.exit_code == 2 and "not JSON" in done.stderr
    assert "Traceback" not in done.output
    done = runner.invoke(
        main, ["evaluate", "blocks-1", str(plan_file), "--backend", "local", "--scheduler", "x:1"]
    )
    assert done.exit_code == 2 and "--backend dask" in done.stderr
    # a plan for another problem: a warning, and it runs ...
    done = runner.invoke(
        main, ["evaluate", "blocks-2", str(plan_file), "--rollouts", "2", "--workers", "1"]
    )
    assert done.exit_code == 0 and "warning" in done.stderr and "planned for" in done.stderr
    # ... unless its objects do not exist there
    b2 = load("blocks-2")
    foreign = tmp_path / "foreign.json"
    doc = plan_document(
        b2, [Place("B", (5.0, 2.5, 0.0))], status="solved", semantics="x", seed=0, search={}
    )
    write_json_atomic(foreign, doc)
    done = runner.invoke(main, ["evaluate", "blocks-1", str(foreign)])
    assert done.exit_code == 2 and "expected an object of problem 'blocks-1'" in done.stderr
    assert "got 'B' (the file was planned for problem 'blocks-2')" in done.stderr


def test_cli_without_dask_says_how_to_install_it(plan_file, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    done = CliRunner().invoke(
        main, ["evaluate", "blocks-1", str(plan_file), "--rollouts", "2", "--backend", "dask"]
    )
    assert done.exit_code == 2
    assert 'pip install "arrange-up[dask]"' in done.stderr


# -- the unified-planning validator -----------------------------------------------------------
def test_the_reliability_validator(blocks1):
    from arrange_up.up.registration import register

    register()
    from unified_planning.engines.results import ValidationResultStatus
    from unified_planning.environment import get_environment
    from unified_planning.shortcuts import PlanValidator

    from arrange_up.up.compile import plan_to_up, to_up

    assert get_environment().factory.engines.count("arrange-up-reliability") == 1
    problem, actions = blocks1
    up_problem = to_up(problem)
    up_plan = plan_to_up(up_problem, actions)
    with PlanValidator(name="arrange-up-reliability", params={"rollouts": 10}) as validator:
        check = validator.validate(up_problem, up_plan)
    assert check.engine_name == "arrange-up-reliability"
    assert check.status in (ValidationResultStatus.VALID, ValidationResultStatus.INVALID)
    for key in ("successes", "trials", "rate", "interval"):
        assert key in check.metrics
    assert check.metrics["trials"] == "10"
    direct = evaluate_plan(problem, actions, rollouts=10, runner=SERIAL)
    assert check.metrics["successes"] == str(direct.successes)
    valid = direct.successes == 10
    assert (check.status is ValidationResultStatus.VALID) == valid
    if not valid:
        assert "rollouts reached the goal" in check.log_messages[0].message
    with pytest.raises(ValueError, match="rollouts must be a positive integer"):
        PlanValidator(name="arrange-up-reliability", params={"rollouts": 0})
