"""What the commands share: clean failures, option parsing, the progress display, summaries."""

from __future__ import annotations

import io
import json
import re
import sys

import click
import pytest
from click.testing import CliRunner
from rich.progress import Progress, TextColumn

from arrange_up.cli import main, shared
from arrange_up.parallel import BACKENDS
from arrange_up.planning.heuristics import HEURISTICS
from arrange_up.planning.planner import DEFAULT_WEIGHT
from arrange_up.repair import DEFAULT_PARTICLES, METHODS
from arrange_up.transitions import available


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def exit_code(call, *args) -> int:
    with pytest.raises(SystemExit) as raised:
        call(*args)
    return raised.value.code


def test_comma_integers_skip_blanks_and_refuse_the_rest(capsys):
    assert shared.comma_integers("--particles", "5,25,,50") == [5, 25, 50]
    assert exit_code(shared.comma_integers, "--particles", "3,x") == shared.EXIT_BAD_INPUT
    assert "--particles: expected comma-separated integers, got '3,x'" in capsys.readouterr().err


def test_the_semantics_check_names_the_registered_ones(capsys):
    shared.check_semantics("particles")
    assert exit_code(shared.check_semantics, "magic") == shared.EXIT_BAD_INPUT
    assert capsys.readouterr().err == (
        "arrange-up: --semantics: unknown semantics 'magic'; expected one of "
        f"{', '.join(available())}\n"
    )


def test_backend_choice():
    assert shared.backend_choice(None, None) == "local"
    assert shared.backend_choice(None, "tcp://x:1") == "dask"
    assert shared.backend_choice("dask", None) == "dask"
    assert exit_code(shared.backend_choice, "local", "tcp://x:1") == shared.EXIT_BAD_INPUT


def test_load_problem_refuses_cleanly(tmp_path, capsys):
    assert exit_code(shared.load_problem, "no-such-domain") == shared.EXIT_BAD_INPUT
    bad = tmp_path / "bad.yaml"
    bad.write_text(
        "name: bad\ntable: {size: [10, 5]}\nobjects: {}\ngoal: {poses: {Z: [1, 1, 0]}}\n"
    )
    assert exit_code(shared.load_problem, str(bad)) == shared.EXIT_BAD_INPUT
    assert "nothing was done" in capsys.readouterr().err


def test_off_a_terminal_progress_is_a_line_every_interval_and_quiet_silences_it(monkeypatch):
    import time

    stream = io.StringIO()
    monkeypatch.setattr(sys, "stderr", stream)
    monkeypatch.setattr(shared, "PROGRESS_INTERVAL", 0.05)
    with shared.terminal_progress(TextColumn("x"), what="evaluate") as display:
        assert isinstance(display, shared.LineProgress)
        task = display.add_task("rollouts", total=200, summary="")
        display.update(task, completed=50, summary="50 ok")
        time.sleep(0.3)  # no further update: the line repeats anyway
    lines = stream.getvalue().splitlines()
    assert len(lines) >= 2
    assert re.fullmatch(
        r"arrange-up evaluate: rollouts 50/200 \(25%\), about \d+:\d\d:\d\d left, 50 ok "
        r"\[0:00:00 elapsed\]",
        lines[0],
    ), lines[0]
    count = len(lines)
    time.sleep(0.2)
    assert len(stream.getvalue().splitlines()) == count  # stopped with the block
    with shared.terminal_progress(TextColumn("x"), quiet=True) as display:
        assert display is None
    monkeypatch.setattr(sys, "stderr", Terminal())
    with shared.terminal_progress(TextColumn("x"), quiet=True) as display:
        assert display is None


def test_the_interval_is_under_the_ten_seconds_the_docs_promise():
    assert 0 < shared.PROGRESS_INTERVAL <= 10


def test_the_progress_display_on_a_terminal_is_gone_after_the_block(monkeypatch):
    monkeypatch.setattr(sys, "stderr", Terminal())
    with shared.terminal_progress(TextColumn("{task.description}")) as display:
        assert isinstance(display, Progress)
        display.add_task("working", total=None)
        assert display.live.is_started
    assert not display.live.is_started


def test_document_summary_puts_the_actions_and_the_output_last():
    document = {"format": "f", "actions": [1, 2], "status": "solved"}
    summary = shared.document_summary(document, "out.json", plan_length=2)
    assert list(summary) == ["format", "status", "plan_length", "actions", "output"]
    assert summary["actions"] == [1, 2] and summary["output"] == "out.json"


def test_echo_json(capsys):
    shared.echo_json({"a": [1]})
    assert json.loads(capsys.readouterr().out) == {"a": [1]}


def options(path: list[str]) -> dict[str, click.Parameter]:
    ctx = click.Context(main)
    command = main
    for name in path:
        command = command.get_command(ctx, name)
    return {param.name: param for param in command.params}


def test_choices_and_defaults_are_the_librarys():
    plan = options(["plan"])
    assert tuple(plan["heuristic"].type.choices) == HEURISTICS
    assert plan["weight"].default == DEFAULT_WEIGHT
    repair = options(["repair"])
    assert tuple(repair["method"].type.choices) == METHODS
    assert repair["particles"].default == DEFAULT_PARTICLES
    for path in (["evaluate"], ["train-cbst"], ["experiment", "fixtures"]):
        assert tuple(options(path)["backend"].type.choices) == BACKENDS


# -- the commands' own checks, through the command line -----------------------------------------
@pytest.mark.parametrize(
    "args",
    [
        ["experiment", "transition-comparison", "--semantics", "magic"],
        ["experiment", "transition-comparison", "--particles", "5,x"],
        ["experiment", "transition-comparison", "--problems", "no-such-problem"],
        ["experiment", "search-table", "--semantics", "magic"],
        ["experiment", "search-table", "--problems", "no-such-problem"],
        ["bench", "physics", "--workers", "x"],
        ["bench", "physics", "--workers", "0"],
        ["train-cbst", "--backend", "local", "--scheduler", "tcp://x:1"],
        ["show", "blocks-2", "--heatmap", "1", "-o", "x.png"],
    ],
)
def test_bad_input_exits_2_before_any_work(args, tmp_path):
    if args[0] == "experiment":
        args = [*args, "--output-dir", str(tmp_path / "results")]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == shared.EXIT_BAD_INPUT, result.output
    assert result.stderr.startswith("arrange-up: ") and "Traceback" not in result.output
    assert not (tmp_path / "results").exists()


def test_plan_and_evaluate_show_their_progress_on_a_terminal(monkeypatch, capsys, tmp_path):
    from arrange_up.cli.evaluate import evaluate
    from arrange_up.cli.plan import plan

    out = tmp_path / "b1.json"
    terminal = Terminal()
    monkeypatch.setattr(sys, "stderr", terminal)
    args = ["blocks-1", "--semantics", "deterministic", "--output", str(out)]
    plan.main(args, standalone_mode=False)
    evaluate.main(
        ["blocks-1", str(out), "--rollouts", "2", "--workers", "1"], standalone_mode=False
    )
    printed = capsys.readouterr().out
    assert "blocks-1: solved" in printed and "of 2 rollouts reached the goal" in printed
    drawn = terminal.getvalue()
    assert "expanded" in drawn and "rollouts" in drawn and "ok (" in drawn


def test_a_failed_output_write_is_one_line_exit_2(tmp_path, monkeypatch):
    # a full disk or /dev/full (not written here: code that replaced the device node would
    # destroy it on a machine running the tests as root)
    import errno

    import arrange_up.cli.problems as problems

    def full(path, text):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(problems, "write_text_atomic", full)
    result = CliRunner().invoke(main, ["export", "blocks-1", "-o", str(tmp_path / "b.pddl")])
    assert result.exit_code == 2, result.output
    assert result.output.strip() == (
        f"arrange-up: {tmp_path / 'b.pddl'}: cannot write: No space left on device"
    )


def test_output_onto_a_symlink_writes_its_target_and_keeps_the_link(tmp_path):
    link = tmp_path / "link.pddl"
    link.symlink_to(tmp_path / "target.pddl")
    assert CliRunner().invoke(main, ["export", "blocks-1", "-o", str(link)]).exit_code == 0
    assert link.is_symlink() and (tmp_path / "target.pddl").read_text().startswith(";")
