"""The arrange-up command: exit statuses, outputs, and clean errors on bad input."""

from __future__ import annotations

import json
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from catalogue import text
from click.testing import CliRunner

from arrange_up.cli import main

REPOSITORY = Path(__file__).resolve().parents[2]

BAD = textwrap.dedent(
    """\
    name: bad
    table: {size: [10, 5]}
    objects:
      A: {kind: gizmo, shape: {box: [1, 1]}}
    goal:
      poses: {Z: [1, 1, 0]}
    """
)


def run(*args: str):
    return CliRunner().invoke(main, list(args), catch_exceptions=False)


def test_help_lists_the_commands():
    result = run("--help")
    assert result.exit_code == 0
    for command in ("plan", "check", "show", "domains", "export", "bench"):
        assert command in result.output


def test_domains_lists_shipped_problems():
    result = run("domains")
    assert result.exit_code == 0
    assert "blocks-4" in result.output and "tz-mating" in result.output


def test_check_accepts_valid_and_reports_every_error(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(BAD)
    result = CliRunner().invoke(main, ["check", str(bad)])
    assert result.exit_code == 2  # bad input, as every command that loads the file says
    assert f"{bad}:4:" in result.output  # the unknown kind, with its line
    assert f"{bad}:6:" in result.output  # the undeclared goal part, with its line
    assert "Traceback" not in result.output


@pytest.mark.parametrize("command", ["check", "plan", "evaluate", "show"])
def test_every_command_exits_2_on_an_invalid_problem_file(tmp_path, command):
    # The contract: bad input exits 2 whatever the command; check's answer about an invalid
    # file is that input being bad, not a negative answer (exit 1) about a good one.
    bad = tmp_path / "bad.yaml"
    bad.write_text(BAD)
    extra = {"evaluate": [str(tmp_path / "plan.json")], "show": ["-o", str(tmp_path / "b.png")]}
    result = CliRunner().invoke(main, [command, str(bad), *extra.get(command, [])])
    assert result.exit_code == 2, result.output
    assert f"{bad}:4:" in result.output and "Traceback" not in result.output


def test_check_valid_shipped_file_by_path():
    from arrange_up.io.domains import resolve_problem

    result = run("check", str(resolve_problem("blocks-2")))
    assert result.exit_code == 0 and "ok: blocks-2" in result.output


def test_check_warns_of_a_controller_too_stiff_for_the_paddle(tmp_path):
    # valid to the format, but the default kp makes an 8 x 0.5 mm paddle's PD unstable
    tiny = tmp_path / "tiny.yaml"
    tiny.write_text(text("millimetre-paddle"))
    result = run("check", str(tiny))
    assert result.exit_code == 0 and "ok: millimetre-paddle" in result.output
    assert f"{tiny}: warning: controller: the compliant controller (kp 300) is too stiff" in (
        result.output
    )
    assert "manipulator 'tip'" in result.output and "give controller.kp at most" in result.output
    assert "warning" not in run("check", "blocks-2").output


def test_a_too_stiff_angle_gain_is_named_with_its_limit_in_the_files_units(tmp_path):
    # an explicit kp_angle too stiff was reported as "kp 300" with a 150-digit rate and a kp
    # limit that could not help; the warning names kp_angle and its limit, per degree
    blocks = (REPOSITORY / "domains" / "blocks-1.yaml").read_text(encoding="utf-8")
    stiff = tmp_path / "stiff.yaml"

    def check(kp_angle: str) -> str:
        stiff.write_text(blocks + f"controller: {{kind: compliant, kp_angle: {kp_angle}}}\n")
        result = run("check", str(stiff))
        assert result.exit_code == 0, result.output
        return result.output

    output = check("1e300")
    assert "(kp_angle 1e+300) is too stiff" in output
    assert "sqrt(kp_angle / I) x dt up to 1.2e+149" in output
    limit = float(re.search(r"give controller.kp_angle at most ([0-9.e+]+),", output)[1])
    assert "too stiff" not in check(f"{limit * 0.99:g}")
    assert "too stiff" in check(f"{limit * 1.01:g}")


def test_show_writes_png(tmp_path):
    out = tmp_path / "b2.png"
    result = run("show", "blocks-2", "--output", str(out))
    assert result.exit_code == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plan_json_summary_and_plan_file(tmp_path):
    out = tmp_path / "plan.json"
    result = run("plan", "blocks-1", "--semantics", "deterministic", "--json", "--output", str(out))
    assert result.exit_code == 0
    summary = json.loads(result.output)
    assert summary["status"] == "solved" and summary["plan_length"] == len(summary["actions"])
    assert summary["search"]["expanded"] >= 1
    document = json.loads(out.read_text())
    assert document["actions"] == summary["actions"]
    assert document["units"] == {"length": "in", "angle": "deg"}


def test_plan_not_found_exits_1_and_writes_honest_status(tmp_path):
    out = tmp_path / "plan.json"
    result = run(
        "plan", "blocks-2", "--semantics", "deterministic", "--max-nodes", "1", "--output", str(out)
    )
    assert result.exit_code == 1
    document = json.loads(out.read_text())
    assert document["status"] == "node-limit" and "actions" not in document


def test_plan_table_is_readable():
    result = run("plan", "blocks-1", "--semantics", "deterministic")
    assert result.exit_code == 0
    assert "place" in result.output and "push" in result.output and "paddle" in result.output


@pytest.mark.parametrize(
    "args",
    [
        ["plan", "no-such-domain"],
        ["plan", "blocks-1", "--semantics", "magic"],
        ["show", "no-such-domain", "--output", "x.png"],
    ],
)
def test_bad_input_exits_2_without_traceback(args):
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 2
    assert "Traceback" not in result.output


def test_bad_problem_file_in_a_subprocess_has_no_traceback(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text(BAD)
    proc = subprocess.run(
        [sys.executable, "-m", "arrange_up", "plan", str(bad)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert f"{bad}:4:" in proc.stderr and "kind" in proc.stderr


def test_export_pddl(tmp_path):
    out = tmp_path / "b2.pddl"
    result = run("export", "blocks-2", "--to", "pddl", "--output", str(out))
    assert result.exit_code == 0
    text = out.read_text()
    assert "(define (problem" in text and ":goal" in text
