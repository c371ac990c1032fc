"""Text from a problem file (a key, an object name, the problem's name) is echoed in messages
escaped: an ANSI escape in a name reaches the terminal as ``\\x1b``, never raw, and ordinary
names read exactly as written.

The command runs with ``color=True`` so that click does not strip ANSI sequences itself (it
does when stderr is not a terminal, which would hide the leak in a test; a user at a terminal
gets what ``color=True`` shows)."""

from __future__ import annotations

import textwrap
from pathlib import Path

from click.testing import CliRunner

from arrange_up.cli import main
from arrange_up.model.errors import Diagnostic, printable

ESC = "\x1b"

PROBLEM = textwrap.dedent(
    """\
    name: "bl\\e[31mocks"
    "\\e[31mfoo": 1
    table: {size: [10, 5]}
    objects:
      A: {kind: part, shape: {box: [1, 1]}}
      paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
    initial:
      A: {pose: [2, 2, 0], uncertainty: [0.1, 0.1, 5]}
    goal:
      tolerance: [0.2, 0.2, 15]
      poses: {A: [5, 2, 0], "\\e[32mB": [1, 1, 0]}
    uncertainty:
      place: [0.2, 0.2, 15]
    """
)


def test_printable_escapes_control_and_format_characters_only() -> None:
    assert printable("paddle_2-left") == "paddle_2-left"
    assert printable("Ä block  Ω") == "Ä block  Ω"
    assert printable("a\x1b[31mb") == "a\\x1b[31mb"
    assert printable("x\u202ey\x00\x7f\x9b") == "x\\u202ey\\x00\\x7f\\x9b"
    assert printable("one\ntwo") == "one\\ntwo"
    assert printable("one\ntwo\x1b", keep_newlines=True) == "one\ntwo\\x1b"


def test_a_diagnostic_escapes_its_key_path_file_and_message() -> None:
    shown = str(Diagnostic(f"p{ESC}.yaml", 3, 1, f"goal.{ESC}[31mB", f"raw {ESC}[2J"))
    assert ESC not in shown
    assert shown == "p\\x1b.yaml:3:1: error: goal.\\x1b[31mB: raw \\x1b[2J"


def test_check_never_sends_a_names_escape_to_the_terminal(tmp_path: Path) -> None:
    path = tmp_path / "ansi.yaml"
    path.write_text(PROBLEM, encoding="utf-8")
    result = CliRunner().invoke(main, ["check", str(path)], color=True)
    assert result.exit_code == 2, result.output
    assert ESC not in result.output
    # the names are still there, escaped, so the user can find them in the file
    assert "\\x1b[31mfoo" in result.output
    assert "goal.poses.\\x1b[32mB" in result.output


def test_check_shows_an_escaped_problem_name_in_its_ok_line(tmp_path: Path) -> None:
    path = tmp_path / "ansi.yaml"
    path.write_text(PROBLEM.replace(', "\\e[32mB": [1, 1, 0]', ""), encoding="utf-8")
    result = CliRunner().invoke(main, ["check", str(path)], color=True)
    assert result.exit_code == 0, result.output
    assert ESC not in result.output
    assert "ok: bl\\x1b[31mocks (1 part" in result.output
