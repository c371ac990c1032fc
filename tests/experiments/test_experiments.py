"""The chapter-3 experiments at toy scale: rows written, resumed, plotted."""

from __future__ import annotations

import csv

from arrange_up.experiments.planning import Planner, search_table, transition_comparison


def rows(path):
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


def test_transition_comparison_writes_rows_and_resumes(tmp_path):
    planners = [
        Planner("deterministic", "deterministic", 1),
        Planner("particles-3", "particles", 3),
    ]
    path = transition_comparison(
        tmp_path, problems=("blocks-1",), planners=planners, runs=2, rollouts=4, workers=1
    )
    first = rows(path)
    assert [(r["planner"], r["run"]) for r in first] == [
        ("deterministic", "0"),
        ("deterministic", "1"),
        ("particles-3", "0"),
        ("particles-3", "1"),
    ]
    assert all(r["status"] == "solved" and int(r["rollouts"]) == 4 for r in first)
    assert all(0.0 <= float(r["reliability"]) <= 1.0 for r in first)
    assert path.with_suffix(".png").stat().st_size > 0
    # A second call finds everything done and adds nothing; a third run is appended.
    transition_comparison(
        tmp_path, problems=("blocks-1",), planners=planners, runs=2, rollouts=4, workers=1
    )
    assert rows(path) == first
    transition_comparison(
        tmp_path, problems=("blocks-1",), planners=planners[:1], runs=3, rollouts=4, workers=1
    )
    assert len(rows(path)) == 5


def test_search_table_rows(tmp_path):
    path = search_table(tmp_path, problems=("blocks-1",), semantics="deterministic")
    table = rows(path)
    assert {(r["search"], r["domination"]) for r in table} == {
        (s, d) for s in ("BFS", "Admiss.", "Inadmiss.") for d in ("yes", "no")
    }
    assert all(r["solved"] == "1" and int(r["cost"]) >= 3 for r in table)
    assert (tmp_path / "search-table-deterministic.png").stat().st_size > 0
