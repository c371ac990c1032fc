"""Ctrl-C during ``arrange-up plan``: the first asks for an orderly stop that keeps what was
computed (a cancelled search is written like any other outcome), the second aborts."""

from __future__ import annotations

import json
import os
import signal
from contextlib import contextmanager
from pathlib import Path

import pytest
from click.testing import CliRunner

from arrange_up.cli import main
from arrange_up.cli import plan as plan_command
from arrange_up.cli.shared import first_interrupt_stops


def test_the_first_interrupt_asks_to_stop_and_the_second_aborts(capsys) -> None:
    with first_interrupt_stops("the test") as interrupted:
        assert not interrupted()
        os.kill(os.getpid(), signal.SIGINT)
        assert interrupted()
        with pytest.raises(KeyboardInterrupt):
            os.kill(os.getpid(), signal.SIGINT)
    assert "interrupt: stopping the test; Ctrl-C again to abort" in capsys.readouterr().err
    # the handler the block found is back
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_an_interrupted_search_is_written_as_cancelled(tmp_path: Path, monkeypatch) -> None:
    @contextmanager
    def interrupted_at_once(what: str):
        yield lambda: True

    monkeypatch.setattr(plan_command, "first_interrupt_stops", interrupted_at_once)
    output = tmp_path / "blocks-4.plan.json"
    result = CliRunner().invoke(
        main, ["plan", "blocks-4", "--particles", "5", "--workers", "1", "-o", str(output)]
    )
    assert result.exit_code == 1, result.output
    assert "blocks-4: cancelled" in result.output and f"wrote {output}" in result.output
    written = json.loads(output.read_text())
    assert written["status"] == "cancelled" and "actions" not in written
