"""The closed-loop benchmark: the paired comparison it prints from committed records, and its
first plan kept for a resumed run."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import pytest
from scipy.stats import binomtest

from arrange_up.io.domains import load

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY / "benchmarks"))
import closed_loop  # noqa: E402
from closed_loop import _sign_test, table  # noqa: E402


def test_sign_test_is_the_exact_two_sided_binomial_test():
    for won, lost in ((24, 4), (18, 4), (23, 16), (3, 3), (0, 5)):
        expected = binomtest(won, won + lost, 0.5).pvalue
        assert abs(_sign_test(won, lost) - expected) < 1e-12
    assert _sign_test(0, 0) == 1.0


def test_the_200_episode_records_print_their_paired_counts():
    printed = table(REPOSITORY / "docs" / "results" / "closed_loop" / "episodes200")
    rows = {line.split(" | ")[0].lstrip("| ").split(".")[0]: line for line in printed.splitlines()}
    assert "82/200 = 41 %" in rows["tz-mating"] and "102/200 = 51 %" in rows["tz-mating"]
    assert "| 24 / 4 (0.00018) |" in rows["tz-mating"]
    assert "| 18 / 4 (0.0043) |" in rows["tt-mating-noisy"]


def test_the_first_plan_is_saved_and_read_back_instead_of_planned_again(tmp_path, monkeypatch):
    problem = load("blocks-2")
    args = argparse.Namespace(plan_semantics="deterministic", plan_particles=10, seed=0)
    path = tmp_path / "blocks-2.plan.json"
    planned = closed_loop.first_plan(problem, args, path)
    assert planned and path.exists()

    def refuse(*_args, **_kwargs):
        raise AssertionError("planned again although the plan file was there")

    monkeypatch.setattr(closed_loop, "plan", refuse)
    assert closed_loop.first_plan(problem, args, path) == planned
    with pytest.raises(SystemExit, match="delete it to plan again"):
        closed_loop.first_plan(load("blocks-3"), args, path)
