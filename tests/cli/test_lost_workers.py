"""A batch whose workers are lost (a loky worker killed during ``evaluate --workers 2`` or
``repair --workers 2``, a Dask scheduler gone) ends in one line, exit 1, that says what was kept
and the command that resumes; never a traceback."""

from __future__ import annotations

import functools
import json
import os
import signal

import pytest
from click.testing import CliRunner

from arrange_up import parallel
from arrange_up.cli import main
from arrange_up.evaluation import evaluate as evaluation
from arrange_up.evaluation.rollouts import rollout_task
from arrange_up.transitions import particles

DOOMED = 6  # the rollout whose worker is killed


def _killed_at_doomed(context, index):
    """A rollout whose worker dies (SIGKILL, as the out-of-memory killer does) at DOOMED."""
    if index == DOOMED:
        os.kill(os.getpid(), signal.SIGKILL)
    return rollout_task(context, index)


def test_a_killed_local_worker_ends_evaluate_in_one_line_that_says_how_to_resume(
    tmp_path, monkeypatch
):
    plan_file, record = tmp_path / "p.json", tmp_path / "r.jsonl"
    made = ["plan", "blocks-1", "--semantics", "deterministic", "-o", str(plan_file), "-q"]
    assert CliRunner().invoke(main, made).exit_code == 0
    args = ["evaluate", "blocks-1", str(plan_file), "--rollouts", "12", "--workers", "2"]
    args += ["--record", str(record), "--quiet"]
    monkeypatch.setattr(evaluation, "rollout_task", _killed_at_doomed)
    lost = CliRunner().invoke(main, args)
    assert lost.exit_code == 1, lost.output
    assert lost.exception is None or isinstance(lost.exception, SystemExit)
    lines = lost.output.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in lost.output, lost.output
    message = lines[0]
    assert message.startswith("arrange-up: a local worker process ended abruptly")
    recorded = [json.loads(line) for line in record.read_text().splitlines()[1:]]
    assert DOOMED not in {line["rollout"] for line in recorded}
    assert f"the {len(recorded)} finished rollouts are in {record}: run again to resume" in message
    assert message.endswith(": arrange-up " + " ".join(args))
    # the command it names resumes: the recorded rollouts are not run again
    monkeypatch.setattr(evaluation, "rollout_task", rollout_task)
    again = CliRunner().invoke(main, args)
    assert again.exit_code == 0, again.output
    assert "of 12 rollouts" in again.output
    assert (f"{len(recorded)} resumed" in again.output) == bool(recorded)


SIMULATE_CHUNK = particles._simulate_chunk


def _killing_chunk(problem, jobs, stop_on_failure, *, parent):
    """A share of the particle semantics' pushes whose worker dies (SIGKILL); simulated as
    usual when it runs in the ``parent`` process (a batch of one share)."""
    if os.getpid() != parent:
        os.kill(os.getpid(), signal.SIGKILL)
    return SIMULATE_CHUNK(problem, jobs, stop_on_failure)


def test_a_killed_worker_of_the_particle_semantics_ends_repair_in_one_line(monkeypatch):
    # the fixture repair simulates on the particle semantics' own pool, not a runner's
    killing = functools.partial(_killing_chunk, parent=os.getpid())
    monkeypatch.setattr(particles, "_simulate_chunk", killing)
    args = ["repair", "blocks-2", "--particles", "4", "--workers", "2", "--quiet"]
    lost = CliRunner().invoke(main, args)
    assert lost.exit_code == 1, lost.output
    assert lost.exception is None or isinstance(lost.exception, SystemExit)
    lines = lost.output.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in lost.output, lost.output
    assert lines[0].startswith("arrange-up: a local worker process ended abruptly")
    assert "no plan was written" in lines[0]


def test_a_lost_dask_batch_is_one_line_not_distributed_s_error():
    pytest.importorskip("distributed")
    from distributed.client import FutureCancelledError

    error = parallel._dask_workers_lost(FutureCancelledError("key", "scheduler-connection-lost"))
    assert isinstance(error, parallel.WorkersLostError) and "\n" not in str(error)
    assert parallel._dask_lost(FutureCancelledError("key", "scheduler-connection-lost"))
    assert not parallel._dask_lost(ValueError("a rollout's own error"))
