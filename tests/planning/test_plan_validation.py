"""Validated particle plans: a found plan is checked on fresh rollouts, and the starts it failed
from join the particles of the next search (``arrange_up.planning.validation``)."""

from __future__ import annotations

import json
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from arrange_up.cli import main
from arrange_up.cli.plan import _status_line
from arrange_up.evaluation.evaluate import evaluate_plan
from arrange_up.evaluation.rollouts import rollout_start, trace_rollout
from arrange_up.io.domains import load
from arrange_up.io.yaml_problem import load_problem
from arrange_up.parallel import SERIAL
from arrange_up.planning import validation as validation_module
from arrange_up.planning.planner import plan
from arrange_up.planning.validation import (
    VALIDATION_REPLANS,
    ValidationRound,
    choose_round,
    research_budget,
    validation_seed,
)

# One block centred on its goal x but spread too wide: two particles do not show the spread,
# and their plan fails about half of the fresh rollouts.
NARROW = Path(__file__).resolve().parents[1] / "problems" / "fresh" / "narrow-squeeze.yaml"


@pytest.fixture(scope="module")
def narrow():
    return load_problem(NARROW)


def test_the_starts_of_failed_validation_rollouts_join_the_next_search(narrow) -> None:
    unvalidated = plan(narrow, particles=2, seed=0, workers=1, validate=0)
    result = plan(narrow, particles=2, seed=0, workers=1, validate=10)
    assert unvalidated.validation is None and unvalidated.solved and result.solved
    validation = result.validation
    assert validation is not None and validation.rollouts == 10
    first, second = validation.rounds[:2]
    # the first search is the unvalidated one, checked on the round-0 validation rollouts
    assert (first.particles, first.expanded) == (2, unvalidated.stats["expanded"])
    seed = validation_seed(0, 0)
    check = evaluate_plan(
        narrow, unvalidated.actions, rollouts=10, seed=seed, runner=SERIAL, keep_records=True
    )
    assert first.successes == check.successes < 10
    failed = [rollout_start(narrow, seed, r.index) for r in check.records if not r.success]
    # at most ``particles`` counterexamples per round, in rollout order
    assert second.particles == 2 + min(2, len(failed))
    # the second search's plan passed: it is returned, planned from the particles plus the
    # first failed starts, and the result still says the 2 particles asked for
    assert second.successes == 10 and validation.passed and validation.chosen == 1
    assert len(validation.rounds) == 2
    assert result.particles == 2
    assert result.beliefs[0].particles == unvalidated.beliefs[0].particles + tuple(failed[:2])
    assert result.actions != unvalidated.actions


def test_progress_numbers_the_searches_a_failed_validation_starts(narrow) -> None:
    snapshots: list[dict] = []
    result = plan(narrow, particles=2, seed=0, workers=1, validate=10, progress=snapshots.append)
    assert len(result.validation.rounds) == 2
    numbers = [s.get("search") for s in snapshots]
    assert numbers[0] is None and numbers[-1] == 2  # the first search unnumbered, then the second
    assert numbers == sorted(numbers, key=lambda n: n or 1)
    assert "search 2 (validation failed): expanded" in _status_line(snapshots[-1])
    assert _status_line(snapshots[0]).startswith("expanded")


def test_a_replan_without_a_plan_is_recorded_and_the_last_plan_found_returned(narrow) -> None:
    # Two nodes solve the two-particle search but not the four-particle one that follows it.
    first = plan(narrow, particles=2, seed=0, workers=1, validate=0, max_nodes=2)
    result = plan(narrow, particles=2, seed=0, workers=1, validate=10, max_nodes=2)
    found, replan = result.validation.rounds
    assert found.successes < 10 and result.validation.chosen == 0
    assert (replan.particles, replan.status, replan.successes) == (4, "node-limit", None)
    assert result.actions == first.actions


def test_a_search_after_the_first_is_limited_to_a_few_times_its_nodes() -> None:
    assert research_budget(10, 5000) == 1000  # the floor
    assert research_budget(300, 5000) == 3000  # ten times the first search's nodes
    assert research_budget(3000, 5000) == 5000  # never beyond the run's limit
    assert research_budget(10, 50) == 50


def test_the_searches_validation_starts_stay_within_their_budget(narrow, monkeypatch) -> None:
    # Unlimited, the second search expands 6 nodes where the first expanded 2; held to the
    # first's count, it stops at its limit and the first plan is returned.
    monkeypatch.setattr(validation_module, "RESEARCH_NODE_FACTOR", 1)
    monkeypatch.setattr(validation_module, "MIN_RESEARCH_NODES", 1)
    result = plan(narrow, particles=2, seed=0, workers=1, validate=10)
    first, second = result.validation.rounds
    assert (first.expanded, second.expanded, second.status) == (2, 2, "node-limit")
    assert result.validation.chosen == 0


def test_a_rollout_start_is_the_first_state_of_its_rollout(narrow) -> None:
    result = plan(narrow, particles=2, seed=0, workers=1, validate=0)
    for index in (0, 3):
        assert rollout_start(narrow, 7, index) == trace_rollout(narrow, result.actions, 7, index)[0]


def test_validation_is_reproducible_and_stops_at_the_first_plan_that_passes(narrow) -> None:
    runs = [plan(narrow, particles=4, seed=1, workers=1, validate=12) for _ in range(2)]
    assert runs[0].actions == runs[1].actions
    assert runs[0].validation == runs[1].validation
    rounds = runs[0].validation.rounds
    assert 1 <= len(rounds) <= VALIDATION_REPLANS + 1
    assert all(r.successes is not None and r.successes < 12 for r in rounds[:-1])
    best = max(r.successes for r in rounds if r.successes is not None)
    assert runs[0].validation.successes == best


def test_validation_seeds_are_apart_from_evaluation_seeds_and_from_each_other() -> None:
    seeds = {validation_seed(seed, round_) for seed in range(3) for round_ in range(4)}
    assert len(seeds) == 12
    assert min(seeds) > 1_000_000  # not a seed a user evaluates with
    assert validation_seed(2, 1) == validation_seed(2, 1)


def test_validation_is_on_by_default_for_the_conformant_semantics(narrow) -> None:
    particles = plan(narrow, particles=3, seed=0, workers=1)
    assert particles.validation is not None and particles.validation.rollouts == 60
    # a CBST plan is checked too: its beliefs are predictions, not bounds (docs/cbst.md)
    cbst = plan(load("blocks-2"), semantics="cbst")
    assert cbst.solved and cbst.validation is not None
    assert cbst.validation.rollouts == cbst.validation.run == 60
    assert [r.particles for r in cbst.validation.rounds] == [None]  # one round, no particles
    assert cbst.particles == 2  # the interval belief's corners, as an unvalidated run says
    assert plan(narrow, semantics="deterministic").validation is None  # a nominal plan
    # a start belief is a posterior, not the initial uncertainty the rollouts draw from
    start = particles.beliefs[0]
    assert plan(narrow, particles=3, seed=0, workers=1, start=start).validation is None


def test_a_deterministic_plan_is_checked_when_asked_and_kept_as_it_did() -> None:
    # The nominal plan of blocks-4 puts the paddle down onto parts in most noisy rollouts:
    # its validation says so, and no further search runs (there are no particles to add).
    problem = load("blocks-4")
    nominal = plan(problem, semantics="deterministic", validate=0)
    checked = plan(problem, semantics="deterministic", validate=20)
    assert checked.solved and checked.actions == nominal.actions
    validation = checked.validation
    assert validation is not None and len(validation.rounds) == 1
    assert validation.run == 20 and validation.successes < 20 and not validation.passed
    line = validation.line()
    assert line.startswith(f"validated on 20 fresh rollouts: {validation.successes} succeeded")
    assert "particles" not in line and "search" not in line


@pytest.mark.parametrize("arguments", [{"validate": -1}, {"validate": 2.5}, {"validate": True}])
def test_bad_validation_arguments_raise(narrow, arguments) -> None:
    with pytest.raises(ValueError, match="validate"):
        plan(narrow, particles=2, **arguments)


def test_the_command_line_reports_and_records_the_validation(tmp_path: Path) -> None:
    output = tmp_path / "narrow.plan.json"
    args = ["plan", str(NARROW), "--particles", "2", "--validate", "10", "--workers", "1"]
    result = CliRunner().invoke(main, [*args, "--json", "-o", str(output)])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.output)
    written = json.loads(output.read_text())
    assert summary["validation"] == written["validation"]
    assert written["validation"]["rollouts"] == 10
    assert [r["particles"] for r in written["validation"]["rounds"]][0] == 2
    assert written["particles"] == 2
    table = CliRunner().invoke(main, args)
    assert "validated on 10 fresh rollouts: 10 succeeded (plan of search 2 of 2" in table.output


def test_the_command_line_validates_other_semantics_as_asked() -> None:
    args = ["plan", str(NARROW), "--semantics", "deterministic"]
    assert "validated" not in CliRunner().invoke(main, args).output
    result = CliRunner().invoke(main, [*args, "--validate", "4"])
    assert result.exit_code == 0, result.output
    assert "validated on 4 fresh rollouts: " in result.output


def test_the_time_limit_holds_while_a_plan_is_validated(narrow) -> None:
    # A million rollouts take hours; the search takes a fraction of a second. Before the
    # limit held during validation, the run took as long as the rollouts.
    started = time.monotonic()
    result = plan(narrow, particles=2, seed=0, workers=1, validate=1_000_000, timeout=2.0)
    assert time.monotonic() - started < 30
    validation = result.validation
    assert result.solved and validation is not None
    assert validation.stopped_by == "the time limit"
    assert 0 <= validation.run < 1_000_000 and not validation.complete
    assert not validation.passed  # never presented as checked on every rollout
    assert "of 1000000 fresh rollouts (stopped by the time limit)" in validation.line() or (
        validation.run == 0 and "not validated: the time limit came before" in validation.line()
    )
    assert result.validation.to_json()["run"] == validation.run


def test_a_stop_request_keeps_the_plan_and_the_rollouts_already_run(narrow, monkeypatch) -> None:
    asked: list[bool] = []

    def evaluate_then_ask(*args, **kwargs):
        # the caller asks to stop once four validation rollouts have finished
        def progress(update) -> None:
            if update.done >= 4:
                asked.append(True)

        return evaluate_plan(*args, progress=progress, **kwargs)

    monkeypatch.setattr(validation_module, "evaluate_plan", evaluate_then_ask)
    result = plan(
        narrow, particles=2, seed=0, workers=1, validate=10, should_stop=lambda: bool(asked)
    )
    validation = result.validation
    # one search, four rollouts: the stop is not mistaken for a failed validation to search on
    assert result.solved and len(validation.rounds) == 1
    assert (validation.run, validation.rollouts, validation.stopped_by) == (4, 10, "a stop request")
    check = evaluate_plan(
        narrow, result.actions, rollouts=4, seed=validation_seed(0, 0), runner=SERIAL
    )
    assert validation.successes == check.successes
    assert "validated on 4 of 10 fresh rollouts (stopped by a stop request)" in validation.line()


def test_the_round_returned_is_the_surest_on_the_rollouts_run() -> None:
    complete = ValidationRound(2, "solved", 5, 8, 10)
    lucky = ValidationRound(4, "solved", 5, 3, 3)  # cut short after three successes
    surer = ValidationRound(4, "solved", 5, 30, 30)  # cut short after thirty
    no_plan = ValidationRound(6, "timeout", 5, None)
    # by the Wilson interval's lower end: 3/3 (0.44) does not beat 8/10 (0.49); 30/30 does
    assert choose_round((complete, lucky, no_plan)) == 0
    assert choose_round((complete, surer, no_plan)) == 1
    # complete rounds: the most successes, the later on a tie
    assert choose_round((complete, ValidationRound(4, "solved", 5, 8, 10))) == 1
    assert choose_round((complete, ValidationRound(4, "solved", 5, 7, 10))) == 0
