"""The long commands report progress on stderr when it is not a terminal (a log, CI, a
notebook): a line every ``shared.PROGRESS_INTERVAL`` seconds, silenced by ``--quiet``."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from arrange_up.cli import main, shared

COMMANDS = {
    "plan": ["plan", "blocks-1", "--workers", "1", "--particles", "5"],
    "repair": ["repair", "blocks-1", "--particles", "2", "--workers", "1"],
    "execute": ["execute", "blocks-1", "--episodes", "2", "--semantics", "deterministic"],
}


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_a_long_command_prints_progress_lines_off_a_terminal_unless_quiet(
    command, monkeypatch, tmp_path
):
    monkeypatch.setattr(shared, "PROGRESS_INTERVAL", 0.02)
    args = COMMANDS[command]
    talking = CliRunner().invoke(main, args)
    assert talking.exit_code == 0, talking.output
    lines = [line for line in talking.stderr.splitlines() if line.startswith("arrange-up ")]
    assert lines and all(line.startswith(f"arrange-up {command}: ") for line in lines)
    assert all(line.endswith(" elapsed]") for line in lines)
    quiet = CliRunner().invoke(main, [*args, "--quiet"])
    assert quiet.exit_code == 0, quiet.output
    assert quiet.stderr == ""


def test_evaluate_lines_say_how_far_and_how_long_is_left(monkeypatch, tmp_path):
    plan = tmp_path / "plan.json"
    made = CliRunner().invoke(
        main, ["plan", "blocks-1", "--semantics", "deterministic", "-o", str(plan), "--quiet"]
    )
    assert made.exit_code == 0, made.output
    monkeypatch.setattr(shared, "PROGRESS_INTERVAL", 0.02)
    result = CliRunner().invoke(
        main, ["evaluate", "blocks-1", str(plan), "--rollouts", "40", "--workers", "1"]
    )
    assert result.exit_code == 0, result.output
    lines = [line for line in result.stderr.splitlines() if "/40 (" in line]
    assert lines, result.stderr
    assert all(line.startswith("arrange-up evaluate: rollouts ") for line in lines)
    assert any(" left" in line for line in lines)


def test_plan_has_a_default_timeout_stated_in_its_help():
    helped = CliRunner().invoke(main, ["plan", "--help"])
    assert "[default: 600.0; x>0]" in " ".join(helped.output.split())
    assert "--quiet" in helped.output
