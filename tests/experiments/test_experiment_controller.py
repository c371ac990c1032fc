"""The controller of the experiments: every problem driven by the kind asked for, recorded in
every row and in the CSV's settings; and the servo's committed measurements, which stay
resumable by the commands of docs/results.md."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

import arrange_up.experiments.fixtures as fixtures
import arrange_up.experiments.planning as planning
from arrange_up.cli import main
from arrange_up.evaluation.records import plan_hash
from arrange_up.experiments.csv_records import CsvAppender, CsvRecordsError, read_csv
from arrange_up.experiments.planning import (
    SEARCH_FIELDS,
    TRANSITION_FIELDS,
    Planner,
    pending_searches,
    pending_transition_runs,
    search_table,
    transition_comparison,
)
from arrange_up.experiments.problems import physics_setting
from arrange_up.io.domains import load
from arrange_up.model.problem import SERVO_CONTROLLER, ControllerKind, driven_by
from arrange_up.parallel import SERIAL
from arrange_up.repair import nominal_plans

SERVO_PROBLEM = driven_by(load("blocks-1"), "servo")
SERVO_RESULTS = Path(__file__).resolve().parents[2] / "docs" / "results" / "servo"
DETERMINISTIC = [Planner("deterministic", "deterministic", 1)]


def settings(path: Path) -> dict:
    return json.loads(path.with_name(f"{path.stem}.settings.json").read_text())


def test_driven_by_gives_the_problem_that_controller():
    problem = load("down-push")
    assert problem.controller.kind is ControllerKind.COMPLIANT
    assert driven_by(problem, "compliant") is problem  # its own controller, gains and all
    servo = driven_by(problem, ControllerKind.SERVO)
    assert servo.controller == SERVO_CONTROLLER and servo.objects == problem.objects
    assert driven_by(servo, "servo") is servo
    with pytest.raises(ValueError, match="unknown controller kind 'stiff'.*compliant, servo"):
        driven_by(problem, "stiff")


def test_the_search_table_is_driven_and_records_the_controller(tmp_path, monkeypatch):
    seen = []
    plan = planning.plan

    def recording(problem, **kwargs):
        seen.append(problem.controller.kind)
        return plan(problem, **kwargs)

    monkeypatch.setattr(planning, "plan", recording)
    path = search_table(tmp_path, problems=("blocks-1",), max_nodes=20, controller="servo")
    assert seen and set(seen) == {ControllerKind.SERVO}
    assert {r["controller"] for r in read_csv(path)} == {"servo"}
    assert settings(path)["controller"] == "servo"
    # Another controller into the same CSV is refused, naming the setting.
    with pytest.raises(CsvRecordsError, match="controller: the CSV's 'servo', this run's"):
        search_table(tmp_path, problems=("blocks-1",), max_nodes=20)
    # By default each problem keeps its own controller (compliant for the shipped ones).
    seen.clear()
    other = search_table(tmp_path / "own", problems=("blocks-1",), max_nodes=20)
    assert set(seen) == {ControllerKind.COMPLIANT}
    assert {r["controller"] for r in read_csv(other)} == {"compliant"}
    assert settings(other)["controller"] == "compliant"


def test_the_transition_comparison_plans_and_evaluates_under_the_controller(tmp_path, monkeypatch):
    seen = []
    evaluate_plan = planning.evaluate_plan

    def recording(problem, actions, **kwargs):
        seen.append(problem.controller.kind)
        return evaluate_plan(problem, actions, **kwargs)

    monkeypatch.setattr(planning, "evaluate_plan", recording)
    args = {"problems": ("blocks-1",), "planners": DETERMINISTIC, "runs": 1, "workers": 1}
    path = transition_comparison(tmp_path, rollouts=2, controller="servo", **args)
    assert seen == [ControllerKind.SERVO]
    (row,) = read_csv(path)
    assert row["controller"] == "servo" and settings(path)["controller"] == "servo"
    with pytest.raises(CsvRecordsError, match="controller"):
        transition_comparison(tmp_path, rollouts=2, controller="compliant", **args)


def test_the_fixture_experiment_repairs_under_the_controller(tmp_path, monkeypatch):
    seen = []
    repair_plan = fixtures.repair_plan

    def recording(problem, actions, **kwargs):
        seen.append(problem.controller.kind)
        return repair_plan(problem, actions, **kwargs)

    monkeypatch.setattr(fixtures, "repair_plan", recording)
    args = {"problems": ("down-push",), "plans": 1, "particles": (3,), "rollouts": 0}
    path = fixtures.fixture_experiment(tmp_path, runner=SERIAL, controller="servo", **args)
    assert seen == [ControllerKind.SERVO, ControllerKind.SERVO]  # the repair and its ablation
    assert {r["controller"] for r in read_csv(path)} == {"servo"}
    assert settings(path)["controller"] == "servo"
    with pytest.raises(CsvRecordsError, match="controller"):
        fixtures.fixture_experiment(tmp_path, runner=SERIAL, **args)


def test_the_cli_option_and_its_refusal(tmp_path):
    args = ["experiment", "search-table", "--problems", "blocks-1", "--semantics"]
    args += ["deterministic", "--max-nodes", "20", "--output-dir", str(tmp_path)]
    first = CliRunner().invoke(main, [*args, "--controller", "servo"])
    assert first.exit_code == 0, first.output
    assert {r["controller"] for r in read_csv(tmp_path / "search-table.csv")} == {"servo"}
    again = CliRunner().invoke(main, [*args, "--controller", "compliant"])
    assert again.exit_code == 2 and "controller" in again.output
    assert "Traceback" not in again.output
    bad = CliRunner().invoke(main, [*args, "--controller", "stiff"])
    assert bad.exit_code == 2
    for command in ("transition-comparison", "search-table", "fixtures"):
        helped = CliRunner().invoke(main, ["experiment", command, "--help"])
        assert "--controller [compliant|servo]" in helped.output


# -- the servo's committed measurements ------------------------------------------------------
@pytest.mark.parametrize(
    ("name", "fields"),
    [
        ("transition-comparison", TRANSITION_FIELDS),
        ("search-table", SEARCH_FIELDS),
        ("fixtures", fixtures.FIXTURE_FIELDS),
    ],
)
def test_the_servo_csvs_load_with_their_controller(tmp_path, name, fields):
    path = SERVO_RESULTS / f"{name}.csv"
    rows = read_csv(path)
    assert rows and list(rows[0]) == fields
    assert {r["controller"] for r in rows} == {"servo"}
    assert settings(path)["controller"] == "servo"
    # The documented commands' settings open the CSV (a copy: opening may write): not refused.
    documented = {
        "transition-comparison": {"rollouts": 300, "max_nodes": 5000, "timeout": None},
        "search-table": {"particles": 1, "max_nodes": 5000, "weight": 1.0, "timeout": None},
        "fixtures": {"rollouts": 1000, "timeout": None},
    }[name]
    copy = tmp_path / path.name
    shutil.copy(path, copy)
    shutil.copy(path.with_name(f"{name}.settings.json"), tmp_path)
    servo = {"controller": "servo", "physics": physics_setting({"p": SERVO_PROBLEM})}
    with CsvAppender(copy, fields, settings={**documented, **servo}):
        pass
    with pytest.raises(CsvRecordsError, match="controller"):
        with CsvAppender(copy, fields, settings={**documented, **servo, "controller": "compliant"}):
            pass


def test_the_physics_settings_are_recorded_and_never_mixed(tmp_path):
    # Each controller's resolved settling and rest settings are a setting of the CSV: rows
    # simulated with the compliant controller's old settings (a settings file without them, as
    # the compliant CSVs measured before it had its own) are refused, not resumed.
    compliant = physics_setting({"p": load("blocks-1")})
    servo = physics_setting({"p": SERVO_PROBLEM})
    assert set(compliant) == {"compliant"} and set(servo) == {"servo"}
    assert compliant["compliant"]["rest_interval"] != servo["servo"]["rest_interval"]
    path = search_table(tmp_path, problems=("blocks-1",), max_nodes=20)
    assert settings(path)["physics"] == compliant
    kept = settings(path)
    del kept["physics"]
    path.with_name(f"{path.stem}.settings.json").write_text(json.dumps(kept))
    with pytest.raises(CsvRecordsError, match="physics: the CSV's None"):
        search_table(tmp_path, problems=("blocks-1",), max_nodes=20)


def test_the_documented_servo_commands_find_every_measurement_done():
    problems = ("blocks-4", "blocks-7")
    planners = [Planner("deterministic", "deterministic", 1), Planner("cbst", "cbst", 1)]
    planners += [Planner(f"particles-{n}", "particles", n) for n in (5, 25, 50)]
    assert pending_transition_runs(SERVO_RESULTS, problems, planners, 3) == []
    searched = ("blocks-1", "blocks-2", "blocks-3", "blocks-4", "blocks-7")
    for semantics in ("deterministic", "cbst"):
        assert pending_searches(SERVO_RESULTS, searched, semantics) == []
    arguments = {"plans": 5, "particles": (10, 40, 150), "seed": 0, "method": "enhanced"}
    problems = fixtures.DEFAULT_PROBLEMS
    assert (
        fixtures.pending_rows(SERVO_RESULTS, problems=problems, ablation=False, **arguments) == []
    )
    # with the ablation the same command would measure only the repairs without fixtures
    pending = fixtures.pending_rows(SERVO_RESULTS, problems=problems, **arguments)
    assert len(pending) == 5 * 5 * 3 and {stage for *_, stage in pending} == {"ablation"}


def test_the_servo_nominal_plans_are_the_ones_the_csv_was_measured_on():
    # A resumed servo run re-makes the nominal plans and refuses a CSV measured on others.
    rows = read_csv(SERVO_RESULTS / "fixtures.csv")
    for name in fixtures.DEFAULT_PROBLEMS:
        found = nominal_plans(driven_by(load(name), "servo"), 5, 0, max_tries=210)
        recorded = {
            int(r["plan"]): r["plan_hash"]
            for r in rows
            if r["problem"] == name and r["stage"] == "nominal"
        }
        assert {j: plan_hash(p) for j, p in enumerate(found)} == recorded, name
