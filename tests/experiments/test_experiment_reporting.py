"""What the experiments tell while and after they run: the duration estimate from measured
costs, the pending measurements, the result tables, the plots of only the rows asked for."""

from __future__ import annotations

import io
import sys

import pytest
from click.testing import CliRunner

from arrange_up.cli import experiments as cli_experiments
from arrange_up.cli import main
from arrange_up.experiments import costs
from arrange_up.experiments.csv_records import read_csv
from arrange_up.experiments.fixtures import pending_rows
from arrange_up.experiments.planning import (
    Planner,
    pending_searches,
    pending_transition_runs,
    search_markdown,
    select_transition_rows,
    transition_comparison,
    transition_markdown,
)

PLANNERS = [Planner("deterministic", "deterministic", 1), Planner("particles-3", "particles", 3)]


def test_durations_read_roughly():
    assert costs.format_duration(0.2) == "1 s"
    assert costs.format_duration(42.4) == "42 s"
    assert costs.format_duration(12 * 60 + 10) == "12 min"
    assert costs.format_duration(3900) == "1 h 05 min"


def test_costs_come_from_the_measured_table_and_scale_with_the_node_limit():
    seconds, nodes = costs.PLANNING_SECONDS["blocks-7", "particles-25"]
    assert costs.planning_cost("blocks-7", "particles-25", 5000) == seconds
    # A lower node limit stops the run earlier: the limit's share of the measured run.
    assert costs.planning_cost("blocks-7", "particles-25", 1000) == pytest.approx(
        seconds * 1000 / nodes
    )
    # A run that hit the measured node limit costs more under a higher one.
    limited, _ = costs.PLANNING_SECONDS["blocks-7", "particles-5"]
    assert costs.planning_cost("blocks-7", "particles-5", 10_000) == pytest.approx(2 * limited)
    assert costs.planning_cost("blocks-9", "deterministic", 5000) is None
    assert costs.rollout_cost("blocks-4", 0) == 0.0
    assert costs.rollout_cost("blocks-4", 100) == pytest.approx(
        100 * costs.ROLLOUT_SECONDS["blocks-4"]
    )
    assert costs.search_cost("cbst", "blocks-2", 0, True, 5000) == 0.04
    assert costs.fixture_cost("down-push", 10, 0) == pytest.approx(1.3)
    assert costs.fixture_cost("nowhere", None, 10) is None
    # a repair without fixtures has its own measured cost, a small share of a full repair's
    ablation = costs.fixture_cost("down-push", 10, 0, fixtures=False)
    assert ablation == pytest.approx(10 * costs.ABLATION_SECONDS_PER_PARTICLE["down-push"])
    assert 0 < ablation < costs.fixture_cost("down-push", 10, 0)
    assert set(costs.ABLATION_SECONDS_PER_PARTICLE) == set(costs.REPAIR_SECONDS_PER_PARTICLE)


def test_the_estimate_says_what_it_does_not_know():
    estimate = costs.Estimate()
    estimate.add(90.0, "blocks-4 deterministic")
    estimate.add(None, "blocks-9 cbst")
    estimate.add(None, "blocks-9 cbst")
    text = estimate.describe(3)
    assert text.startswith("3 measurements to make; about 2 min for 1 of them")
    assert "no measured cost for blocks-9 cbst)" in text
    assert costs.Estimate().describe(0).startswith("nothing to measure")


def test_pending_measurements_leave_out_what_the_csv_holds(tmp_path):
    assert len(pending_transition_runs(tmp_path, ["blocks-1"], PLANNERS, 2)) == 4
    transition_comparison(
        tmp_path, problems=("blocks-1",), planners=PLANNERS[:1], runs=1, rollouts=0, workers=1
    )
    assert pending_transition_runs(tmp_path, ["blocks-1"], PLANNERS, 2) == [
        ("blocks-1", "deterministic", 1),
        ("blocks-1", "particles-3", 0),
        ("blocks-1", "particles-3", 1),
    ]
    assert len(pending_searches(tmp_path, ["blocks-1", "blocks-2"], "cbst")) == 12
    assert (
        pending_rows(
            tmp_path, problems=["down-push"], plans=2, particles=[10, 40], seed=0, method="enhanced"
        )
        == [
            ("down-push", None, "nominal"),
            ("down-push", 10, "repaired"),
            ("down-push", 10, "ablation"),
            ("down-push", 40, "repaired"),
            ("down-push", 40, "ablation"),
        ]
        * 2
    )
    assert pending_rows(
        tmp_path, problems=["down-push"], plans=1, particles=[10], seed=0, method="enhanced",
        ablation=False,
    ) == [("down-push", None, "nominal"), ("down-push", 10, "repaired")]  # fmt: skip


def test_tables_and_plots_show_only_the_rows_asked_for_with_node_limits(tmp_path):
    measured = []
    path = transition_comparison(
        tmp_path,
        problems=("blocks-1", "blocks-2"),
        planners=PLANNERS[:1],
        runs=1,
        rollouts=2,
        max_nodes=4,
        workers=1,
        measured=measured.append,
    )
    assert [(r["problem"], r["status"]) for r in measured] == [
        ("blocks-1", "solved"),
        ("blocks-2", "node-limit"),
    ]
    # A later call on blocks-1 alone (the CSV's settings): its plot and table leave blocks-2 out.
    transition_comparison(
        tmp_path,
        problems=("blocks-1",),
        planners=PLANNERS[:1],
        runs=1,
        rollouts=2,
        max_nodes=4,
        workers=1,
    )
    rows = select_transition_rows(read_csv(path), ["blocks-1"], ["deterministic"], 1)
    assert [r["problem"] for r in rows] == ["blocks-1"]
    both = select_transition_rows(read_csv(path), ["blocks-2", "blocks-1"], ["deterministic"], 1)
    table = transition_markdown(both)
    lines = table.splitlines()
    assert lines[2].startswith("| blocks-2 | deterministic | 0/1 (1 node limit) |")
    assert lines[2].endswith("| node limit |")
    assert lines[3].startswith("| blocks-1 | deterministic | 1/1 |") and "% of 2" in lines[3]


def test_the_search_table_names_how_unsolved_searches_ended():
    rows = [
        {"search": "BFS", "domination": "no", "problem": "blocks-1", "status": "solved",
         "solved": "1", "expanded": "7", "cost": "3"},
        {"search": "BFS", "domination": "no", "problem": "blocks-2", "status": "node-limit",
         "solved": "0", "expanded": "20", "cost": ""},
    ]  # fmt: skip
    lines = search_markdown(rows).splitlines()
    assert lines[0] == "| search | domination | solved | blocks-1 | blocks-2 |"
    assert lines[2] == "| BFS | no | 1/2 | 7 / 3 | node limit (20) |"


def test_the_command_estimates_reports_each_run_and_prints_the_table(tmp_path, monkeypatch):
    monkeypatch.setattr(cli_experiments, "available", lambda: ("deterministic", "particles"))
    # Only blocks-4's deterministic planner is in the measured table: the estimate says so.
    result = CliRunner().invoke(
        main,
        [
            "experiment", "transition-comparison", "--problems", "blocks-1,blocks-4",
            "--particles", "3", "--runs", "1", "--rollouts", "2", "--max-nodes", "4",
            "--workers", "1", "--output-dir", str(tmp_path),
        ],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    err = result.stderr.splitlines()
    assert "estimate: 4 measurements to make; about" in err[0]
    assert "for 1 of them" in err[0] and "no measured cost for blocks-1 deterministic" in err[0]
    done = [line for line in err if "done," in line]
    assert len(done) == 4
    assert any("blocks-4 deterministic run 1: no plan: node limit after 4 nodes" in line
               for line in done)  # fmt: skip
    assert "4/4 done" in done[-1]
    out = result.stdout.splitlines()
    assert out[0].startswith("| problem | planner | runs solved |")
    assert any(line.startswith("| blocks-4 | particles-3 | 0/1 (1 node limit)") for line in out)
    assert out[-1].startswith("wrote ")


@pytest.mark.parametrize("command", ["transition-comparison", "search-table", "fixtures"])
def test_an_experiment_without_problems_is_refused(command, tmp_path):
    for problems in ("", ","):
        result = CliRunner().invoke(
            main, ["experiment", command, "--problems", problems, "--output-dir", str(tmp_path)]
        )
        assert result.exit_code == 2 and "--problems: expected at least one problem" in (
            result.output
        )
    assert not any(tmp_path.iterdir())  # nothing written


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_on_a_terminal_the_runs_print_above_a_live_line(monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(cli_experiments, "available", lambda: ("deterministic", "particles"))
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    cli_experiments.experiment.main(
        [
            "transition-comparison", "--problems", "blocks-1", "--particles", "3",
            "--runs", "1", "--rollouts", "0", "--workers", "1", "--output-dir", str(tmp_path),
        ],
        standalone_mode=False,
    )  # fmt: skip
    drawn = terminal.getvalue()
    assert "estimate: 2 measurements to make" in drawn
    assert "blocks-1 deterministic run 1: solved in" in drawn
    assert "blocks-1 particles-3 run 1: solved in" in drawn
    assert "2/2" in drawn  # the live line's count
    assert capsys.readouterr().out.startswith("| problem | planner | runs solved |")
