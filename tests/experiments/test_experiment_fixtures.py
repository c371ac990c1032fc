"""The chapter-4 fixture experiment at toy scale: rows, resume, honest statuses, CLI."""

from __future__ import annotations

import csv

import pytest
from click.testing import CliRunner

import arrange_up.experiments.fixtures as experiment
from arrange_up.cli import main
from arrange_up.experiments.fixtures import (
    FAILURE_KINDS,
    FIXTURE_FIELDS,
    NO_PLAN,
    StaleResultsError,
    fixture_experiment,
    markdown_table,
    read_rows,
    summarize,
)
from arrange_up.io.domains import resolve_problem
from arrange_up.parallel import SERIAL

TINY = {"plans": 1, "particles": (3, 5), "rollouts": 5, "runner": SERIAL, "ablation": False}


def rows(path):
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


def forbid(monkeypatch, *names):
    """Make the repair and the evaluation fail loudly if they are called."""

    def refuse(*_args, **_kwargs):
        raise AssertionError("measured again although the CSV holds the row")

    if "repair" in names:
        monkeypatch.setattr(experiment, "repair_plan", refuse)
    if "evaluate" in names:
        monkeypatch.setattr(experiment, "evaluate_plan", refuse)


def test_rows_plots_and_resume(tmp_path, monkeypatch):
    path = fixture_experiment(tmp_path, problems=("down-push",), **TINY)
    first = rows(path)
    assert [(r["stage"], r["particles"], r["method"]) for r in first] == [
        ("nominal", "", ""),
        ("repaired", "3", "enhanced"),
        ("repaired", "5", "enhanced"),
    ]
    nominal, *repaired = first
    assert nominal["status"] == "solved" and nominal["plan_hash"].startswith("sha256:")
    for row in first:
        assert row["plan_hash"] == nominal["plan_hash"]  # every row names the nominal plan
        assert int(row["rollouts"]) == 5 and 0 <= int(row["successes"]) <= 5
        assert float(row["reliability"]) == int(row["successes"]) / 5
        failed = sum(int(row[kind]) for kind in FAILURE_KINDS)
        assert failed == 5 - int(row["successes"])  # every failed rollout has its kind
    for row in repaired:
        assert row["status"] == "solved" and float(row["seconds"]) > 0
        assert int(row["plan_length"]) >= int(row["nominal_length"]) >= 1
        assert int(row["simulations"]) > 0
    for name in ("fixtures-overview.png", "fixtures-down-push.png"):
        assert (tmp_path / name).stat().st_size > 0

    # Resuming measures nothing: the CSV is unchanged, seconds and all.
    forbid(monkeypatch, "repair", "evaluate")
    fixture_experiment(tmp_path, problems=("down-push",), **TINY)
    assert rows(path) == first
    monkeypatch.undo()

    # A new particle count adds exactly its row, without redoing the nominal evaluation.
    calls = []
    repair_plan, evaluate_plan = experiment.repair_plan, experiment.evaluate_plan

    def counting_repair(*args, **kwargs):
        calls.append(("repair", kwargs["particles"]))
        return repair_plan(*args, **kwargs)

    def counting_evaluate(problem, actions, **kwargs):
        calls.append(("evaluate", len(actions)))
        return evaluate_plan(problem, actions, **kwargs)

    monkeypatch.setattr(experiment, "repair_plan", counting_repair)
    monkeypatch.setattr(experiment, "evaluate_plan", counting_evaluate)
    fixture_experiment(tmp_path, problems=("down-push",), **{**TINY, "particles": (3, 4)})
    assert [what for what, _ in calls] == ["repair", "evaluate"] and calls[0][1] == 4
    assert rows(path)[:3] == first and rows(path)[3]["particles"] == "4"


def test_a_problem_without_nominal_plan_is_recorded_not_skipped(tmp_path, monkeypatch):
    # As if the deterministic planner found no plan for down-push.
    monkeypatch.setattr(experiment, "nominal_plans", lambda *_args, **_kwargs: [])
    path = fixture_experiment(tmp_path, problems=("down-push",), **{**TINY, "plans": 2})
    table = rows(path)
    assert [(r["plan"], r["stage"], r["status"]) for r in table] == [
        ("0", "nominal", NO_PLAN),
        ("1", "nominal", NO_PLAN),
    ]
    assert all("no nominal plan" in r["reason"] and r["reliability"] == "" for r in table)
    (summary,) = summarize(read_rows(path))
    assert (summary.plans, summary.solved, summary.statuses) == (2, 0, ((NO_PLAN, 2),))
    assert "0/2 (2 no-plan)" in markdown_table([summary])
    assert (tmp_path / "fixtures-down-push.png").stat().st_size > 0


class FailedRepair:
    """What a failed repair_plan returns, as far as the experiment reads it."""

    status = "failed"
    actions = None
    reason = "step 1 (push): every candidate is invalid"
    elapsed = 0.5
    simulations = 7

    def stats(self):
        return {"pushes": 1, "fixtures_placed": 0}


def test_failed_and_raising_repairs_are_recorded_with_their_reason(tmp_path, monkeypatch):
    def fake(problem, actions, *, particles, **_kwargs):
        if particles == 3:
            return FailedRepair()
        raise ValueError("not a nominal plan of this problem")

    monkeypatch.setattr(experiment, "repair_plan", fake)
    path = fixture_experiment(tmp_path, problems=("down-push",), **TINY)
    _, failed, error = rows(path)
    assert (failed["status"], failed["reason"]) == ("failed", FailedRepair.reason)
    assert (error["status"], error["reason"]) == ("error", "not a nominal plan of this problem")
    for row in (failed, error):  # no plan, so nothing evaluated and no length
        assert row["rollouts"] == row["reliability"] == row["plan_length"] == ""
    summary = summarize(read_rows(path))
    assert [(s.particles, s.solved, s.statuses) for s in summary[1:]] == [
        (3, 0, (("failed", 1),)),
        (5, 0, (("error", 1),)),
    ]
    assert "0/1 (1 failed)" in markdown_table(summary)


def test_rows_of_another_nominal_plan_are_refused(tmp_path):
    with (tmp_path / "fixtures.csv").open("w", newline="") as handle:
        writer = csv.DictWriter(handle, FIXTURE_FIELDS)
        writer.writeheader()
        row = dict.fromkeys(FIXTURE_FIELDS, "")
        row.update(problem="down-push", seed=0, plan=0, stage="nominal", plan_hash="sha256:old")
        writer.writerow(row)
    with pytest.raises(StaleResultsError, match="another nominal plan"):
        fixture_experiment(tmp_path, problems=("down-push",), **TINY)


def test_a_csv_with_other_columns_is_refused(tmp_path):
    (tmp_path / "fixtures.csv").write_text("problem,seed,plan\ndown-push,0,0\n")
    with pytest.raises(StaleResultsError, match="columns"):
        fixture_experiment(tmp_path, problems=("down-push",), **TINY)
    assert (tmp_path / "fixtures.csv").read_text() == "problem,seed,plan\ndown-push,0,0\n"


def invoke(*args):
    return CliRunner().invoke(main, ["experiment", "fixtures", *args], catch_exceptions=False)


def test_cli_writes_csv_pngs_and_table_and_resumes(tmp_path):
    args = ["--plans", "1", "--particles", "3", "--rollouts", "5", "--workers", "1"]
    args += ["--problems", "down-push", "--output-dir", str(tmp_path)]
    result = invoke(*args)
    assert result.exit_code == 0, result.output
    table = rows(tmp_path / "fixtures.csv")
    assert [(r["problem"], r["stage"], r["status"]) for r in table] == [
        ("down-push", "nominal", "solved"),
        ("down-push", "repaired", "solved"),
        ("down-push", "ablation", "solved"),  # on by default
    ]
    for name in ("overview", "down-push"):
        assert (tmp_path / f"fixtures-{name}.png").stat().st_size > 0
    assert "| down-push | nominal | — | 1/1 |" in result.output
    assert "| down-push | repaired | 3 | 1/1 |" in result.output
    assert "| down-push | repaired, no fixtures | 3 | 1/1 |" in result.output
    assert "fixtures' own share" in result.output
    again = invoke(*args)
    assert again.exit_code == 0 and rows(tmp_path / "fixtures.csv") == table


@pytest.mark.parametrize(
    "args",
    [["--particles", "3,x"], ["--particles", "0"], ["--problems", "no-such-problem"]],
)
def test_cli_bad_input_exits_2(tmp_path, args):
    result = CliRunner().invoke(
        main, ["experiment", "fixtures", "--output-dir", str(tmp_path), *args]
    )
    assert result.exit_code == 2 and "Traceback" not in result.output
    assert not (tmp_path / "fixtures.csv").exists()


def test_help_teaches(tmp_path):
    result = invoke("--help")
    assert result.exit_code == 0
    for text in ("fixtures.csv", "fixtures-overview.png", "resumes", "Examples", "no-plan"):
        assert text in result.output


def test_cli_refuses_a_foreign_csv_with_exit_2(tmp_path):
    (tmp_path / "fixtures.csv").write_text("problem,seed,plan\n")
    result = CliRunner().invoke(
        main, ["experiment", "fixtures", "--problems", "down-push", "--output-dir", str(tmp_path)]
    )
    assert result.exit_code == 2 and "another output directory" in result.output


# -- the fixtures' ablation ----------------------------------------------------------------------
def test_the_ablation_rows_are_the_same_repairs_without_fixtures(tmp_path, monkeypatch):
    calls = []
    repair_plan = experiment.repair_plan

    def recording(problem, actions, **kwargs):
        calls.append((kwargs["particles"], kwargs["seed"], kwargs["method"], kwargs["fixtures"]))
        return repair_plan(problem, actions, **kwargs)

    monkeypatch.setattr(experiment, "repair_plan", recording)
    # seed 2, 5 particles: the full repair of down-push places the bar
    args = {**TINY, "particles": (5,), "seed": 2}
    path = fixture_experiment(tmp_path, problems=("down-push",), **{**args, "ablation": True})
    nominal, repaired, ablation = rows(path)
    assert [r["stage"] for r in (nominal, repaired, ablation)] == [
        "nominal",
        "repaired",
        "ablation",
    ]
    assert calls == [(5, 2, "enhanced", True), (5, 2, "enhanced", False)]
    assert int(repaired["fixtures_placed"]) >= 1
    assert ablation["status"] == "solved" and ablation["fixtures_placed"] == "0"
    assert (ablation["particles"], ablation["method"]) == ("5", "enhanced")
    assert ablation["plan_hash"] == nominal["plan_hash"]
    assert int(ablation["rollouts"]) == 5  # evaluated on the same rollouts
    assert int(ablation["plan_length"]) == int(nominal["plan_length"])  # no place, no pick

    summary = summarize(read_rows(path))
    assert [(s.stage, s.particles) for s in summary] == [
        ("nominal", None),
        ("repaired", 5),
        ("ablation", 5),
    ]
    share = float(repaired["reliability"]) - float(ablation["reliability"])
    ((problem, count, with_fixtures, without),) = experiment.fixture_shares(summary)
    assert (problem, count) == ("down-push", 5)
    assert with_fixtures - without == pytest.approx(share)
    table = markdown_table(summary)
    assert "| down-push | repaired, no fixtures | 5 | 1/1 |" in table
    assert f"| {100 * share:+.1f} |" in table
    assert (tmp_path / "fixtures-down-push.png").stat().st_size > 0

    # Without ablation rows the table is as it always was: no share table.
    assert "own share" not in markdown_table([s for s in summary if s.stage != "ablation"])


def test_turning_the_ablation_on_later_measures_only_its_rows(tmp_path, monkeypatch):
    args = {**TINY, "particles": (3,), "rollouts": 0}
    path = fixture_experiment(tmp_path, problems=("down-push",), **args)
    first = rows(path)
    assert [r["stage"] for r in first] == ["nominal", "repaired"]
    assert experiment.pending_rows(
        tmp_path, problems=["down-push"], plans=1, particles=[3], seed=0, method="enhanced"
    ) == [("down-push", 3, "ablation")]
    calls = []
    repair_plan = experiment.repair_plan

    def recording(problem, actions, **kwargs):
        calls.append(kwargs["fixtures"])
        return repair_plan(problem, actions, **kwargs)

    monkeypatch.setattr(experiment, "repair_plan", recording)
    fixture_experiment(tmp_path, problems=("down-push",), **{**args, "ablation": True})
    assert calls == [False]
    assert rows(path)[:2] == first and rows(path)[2]["stage"] == "ablation"


def test_a_problem_given_as_a_file_gets_a_picture_named_after_the_file(tmp_path):
    # The CSV records the path; the picture is named by the file's stem, in the output folder.
    source = resolve_problem("down-push").read_text(encoding="utf-8")
    problem_file = tmp_path / "problems" / "down-push-copy.yaml"
    problem_file.parent.mkdir()
    problem_file.write_text(source.replace("name: down-push", "name: down-push-copy"))
    out = tmp_path / "out"
    args = ["--plans", "1", "--particles", "3", "--rollouts", "5", "--workers", "1"]
    result = invoke(
        *args, "--no-ablation", "--problems", str(problem_file), "--output-dir", str(out)
    )
    assert result.exit_code == 0, result.output
    assert (out / "fixtures-down-push-copy.png").stat().st_size > 0
    assert f"| {problem_file} | nominal |" in result.output
