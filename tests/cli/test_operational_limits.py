"""Limits that keep a command's cost bounded: a worker count beyond what the machine can use,
and a rollout count whose work could never finish, are refused with exit 2 and one line that
names the option and the limit, before any work (no process started, no list built); within
the limits, the rollouts to do are drawn lazily.
"""

from __future__ import annotations

import time
import tracemalloc

import pytest
from click.testing import CliRunner

from arrange_up import parallel
from arrange_up.cli import main
from arrange_up.evaluation.evaluate import MAX_ROLLOUTS, evaluate_plan
from arrange_up.parallel import SERIAL, RunnerConfig, check_workers, local_executor, max_workers

# every command that takes --workers; where a problem is named it is one that does not exist,
# so that a command that failed to refuse the count ends at once (exit 2, another message)
WORKER_COMMANDS = {
    "plan": ["plan", "no-such-problem"],
    "evaluate": ["evaluate", "no-such-problem", "plan.json"],
    "repair": ["repair", "no-such-problem"],
    "experiment fixtures": ["experiment", "fixtures", "--problems", "no-such-problem"],
    "experiment transition-comparison": [
        "experiment",
        "transition-comparison",
        "--problems",
        "no-such-problem",
    ],
    "train-cbst": ["train-cbst", "--output-dir", "out"],
    "rescore-cbst": ["rescore-cbst", "compliant", "--test-data", "t.jsonl"],
    "bench physics": ["bench", "physics"],
}


@pytest.mark.parametrize("command", sorted(WORKER_COMMANDS))
def test_every_workers_option_refuses_more_than_the_limit(command, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    too_many = max_workers() + 1
    result = CliRunner().invoke(main, [*WORKER_COMMANDS[command], "--workers", str(too_many)])
    assert result.exit_code == 2, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit)
    assert f"at most {max_workers()}" in result.output and str(too_many) in result.output
    assert "--workers" in result.output


@pytest.mark.parametrize("command", sorted(WORKER_COMMANDS))
def test_every_workers_option_states_its_limit_in_help(command):
    result = CliRunner().invoke(main, [*command.split(), "--help"])
    assert result.exit_code == 0
    help_text = " ".join(result.output.split())
    assert f"At most {parallel.WORKERS_PER_CORE} per core ({max_workers()} here)" in help_text


def test_the_library_refuses_the_same_counts():
    limit = max_workers()
    assert limit == parallel.WORKERS_PER_CORE * parallel.available_cores()
    check_workers(limit)  # the limit itself is allowed
    for bad in (limit + 1, 1024):
        if bad <= limit:
            continue
        with pytest.raises(ValueError, match=f"at most {limit}"):
            check_workers(bad)
        with pytest.raises(ValueError, match=f"at most {limit}"):
            RunnerConfig(workers=bad)
        with pytest.raises(ValueError, match=f"at most {limit}"):
            local_executor(bad)  # refused before loky starts anything


def test_bench_physics_refuses_before_its_first_measurement():
    from arrange_up.physics.bench import bench_physics

    lines: list[str] = []
    began = time.perf_counter()
    with pytest.raises(ValueError, match="at most"):
        bench_physics(n_pushes=10, workers=(1, max_workers() + 1), progress=lines.append)
    assert not lines and time.perf_counter() - began < 5.0


# every command that takes a count of rollouts
ROLLOUT_OPTIONS = {
    "evaluate": ["evaluate", "no-such-problem", "plan.json", "--rollouts"],
    "plan --validate": ["plan", "no-such-problem", "--validate"],
    "experiment fixtures": [
        "experiment",
        "fixtures",
        "--problems",
        "no-such-problem",
        "--rollouts",
    ],
    "experiment transition-comparison": [
        "experiment",
        "transition-comparison",
        "--problems",
        "no-such-problem",
        "--rollouts",
    ],
}


@pytest.mark.parametrize("command", sorted(ROLLOUT_OPTIONS))
@pytest.mark.parametrize("count", [MAX_ROLLOUTS + 1, 99999999999999999999])
def test_rollout_counts_beyond_the_limit_are_refused_at_once(command, count, tmp_path, monkeypatch):
    # evaluate --rollouts 99999999999999999999 built its to-do list first: 6 GB in 59 s
    monkeypatch.chdir(tmp_path)
    began = time.perf_counter()
    result = CliRunner().invoke(main, [*ROLLOUT_OPTIONS[command], str(count)])
    assert result.exit_code == 2, result.output
    assert f"{count} is not in the range" in result.output and f"{MAX_ROLLOUTS}" in result.output
    assert time.perf_counter() - began < 5.0


def test_the_library_refuses_the_same_rollout_counts():
    from arrange_up.io.domains import load
    from arrange_up.planning.validation import check_validate

    problem = load("blocks-1")
    with pytest.raises(ValueError, match="rollouts must be at most 1,000,000"):
        evaluate_plan(problem, (), rollouts=MAX_ROLLOUTS + 1, runner=SERIAL)
    with pytest.raises(ValueError, match="validate must be at most 1,000,000"):
        check_validate(MAX_ROLLOUTS + 1)
    check_validate(MAX_ROLLOUTS)


def test_the_rollouts_to_do_are_drawn_lazily():
    # an evaluation of the most rollouts, stopped after a few: the to-do costs no memory (a
    # list of a million indices takes about 36 MB)
    from arrange_up.io.domains import load

    problem = load("blocks-1")
    done: list[int] = []
    tracemalloc.start()
    try:
        result = evaluate_plan(
            problem,
            (),
            rollouts=MAX_ROLLOUTS,
            runner=SERIAL,
            progress=lambda state: done.append(state.done),
            should_stop=lambda: len(done) > 3,
        )
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert result.trials == 3
    assert peak < 4_000_000, peak


def test_a_table_of_1e300_is_planned_within_the_timeout(tmp_path):
    # the place rings about the grid ran to the table's size in steps of the grid before the
    # search began (1e300 / 0.1 rings), past --timeout: at most MAX_RINGS are built now
    from arrange_up.planning.generators.places import MAX_RINGS, rings

    start = time.monotonic()
    assert len(rings(((0.5, 0.0), (0.0, 0.5)), 1e300)) == MAX_RINGS
    assert len(rings(((0.5, 0.0), (0.0, 0.5)), 10.0)) == 19  # a real table: every ring
    problem = tmp_path / "huge.yaml"
    problem.write_text(
        "name: huge\ntable: {size: [1e300, 1e300]}\nobjects:\n"
        "  A: {kind: part, shape: {box: [1, 1]}}\n"
        "  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}\n"
        "goal:\n  tolerance: [0.2, 0.2]\n  poses: {A: [5, 2, 0]}\n"
    )
    args = ["plan", str(problem), "--semantics", "deterministic", "--workers", "1"]
    result = CliRunner().invoke(main, [*args, "--timeout", "30", "--quiet"])
    assert result.exit_code in (0, 1), result.output
    assert time.monotonic() - start < 60
