"""`arrange-up plan --backend dask`: the runner is made only for a semantics that simulates
pushes; bad or unreachable backends still exit 2."""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from arrange_up import parallel
from arrange_up.cli import main
from arrange_up.io.resources import shipped_dir

#: A port nothing listens on: connecting is refused until the client's timeout.
NOWHERE = "tcp://127.0.0.1:1"


def _servo_blocks_2(folder: Path) -> Path:
    """blocks-2 under the servo, the controller whose shipped CBST model plans it."""
    problem = folder / "blocks-2-servo.yaml"
    source = shipped_dir("domains", "the shipped domains") / "blocks-2.yaml"
    problem.write_text(source.read_text() + "controller: {kind: servo}\n")
    return problem


@pytest.fixture
def no_dask_runner(monkeypatch):
    """Any attempt to make a Dask runner (a LocalCluster or a client) fails the test."""

    def refuse(self, *args, **kwargs):
        raise AssertionError("a Dask runner was made")

    monkeypatch.setattr(parallel.DaskRunner, "__init__", refuse)


def test_a_cbst_plan_on_dask_starts_no_cluster(tmp_path, no_dask_runner):
    problem = _servo_blocks_2(tmp_path)
    args = ["plan", str(problem), "--semantics", "cbst", "--backend", "dask", "--workers", "2"]
    result = CliRunner().invoke(main, args)
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    assert result.exit_code == 0, result.output
    assert "solved (cbst, interval belief, seed 0)" in result.output  # no "2 particles"
    assert "validated on 60 fresh rollouts: 60 succeeded" in result.output


def test_a_cbst_plan_does_not_reach_for_the_scheduler(tmp_path, no_dask_runner):
    problem = _servo_blocks_2(tmp_path)
    args = ["plan", str(problem), "--semantics", "cbst", "--scheduler", NOWHERE]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 0, result.output


def test_a_cbst_plan_still_refuses_a_scheduler_with_the_local_backend(tmp_path, no_dask_runner):
    problem = _servo_blocks_2(tmp_path)
    args = ["plan", str(problem), "--semantics", "cbst", "--backend", "local"]
    result = CliRunner().invoke(main, [*args, "--scheduler", NOWHERE])
    assert result.exit_code == 2 and "--scheduler" in result.output, result.output


def test_an_unreachable_scheduler_exits_2_for_a_semantics_that_simulates_pushes():
    pytest.importorskip("distributed")
    args = ["plan", "blocks-1", "--particles", "2", "--max-nodes", "1", "--workers", "1"]
    result = CliRunner().invoke(main, [*args, "--scheduler", NOWHERE])
    assert result.exception is None or isinstance(result.exception, SystemExit), result.exception
    assert result.exit_code == 2, result.output
    assert "cannot reach the Dask scheduler" in result.output and NOWHERE in result.output
    assert "Traceback" not in result.output
