"""What every command tells the user: the warnings of the problem it loads, ``check`` on
shipped names and mixed arguments, figures in the format their name says, plan files that
respect the umask."""

from __future__ import annotations

import json
import os
import stat
import textwrap
from pathlib import Path

import pytest
from catalogue import text
from click.testing import CliRunner

from arrange_up.cli import main

REPOSITORY = Path(__file__).resolve().parents[2]

TYPO = textwrap.dedent(
    """\
    name: typo
    table: {size: [10, 5]}
    objects:
      A: {kind: part, shape: {box: [1, 1]}}
      paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
    goal:
      tolerence: [0.5, 0.5]
      poses: {A: [9.5, 0.5, 0]}
    uncertainty:
      friction: [0.5, 1000000]
    """
)


def run(*args: str):
    return CliRunner().invoke(main, list(args), catch_exceptions=False)


@pytest.fixture
def typo(tmp_path: Path) -> Path:
    path = tmp_path / "typo.yaml"
    path.write_text(TYPO)
    return path


def _warned(output: str, path: Path) -> None:
    # the misspelt key, where it is, and the default it means; the absurd friction, and why
    assert f"{path}:7:3: warning: goal.tolerence: unknown key 'tolerence'" in output
    assert "did you mean 'tolerance'" in output
    assert f"{path}:7:3: warning: goal.tolerance: no tolerance given; using the default" in output
    assert f"{path}:10:13: warning: uncertainty.friction: friction up to 1e+06" in output


def test_plan_reports_the_warnings_check_reports(typo):
    checked = run("check", str(typo))
    assert checked.exit_code == 0
    _warned(checked.output, typo)
    planned = run("plan", str(typo), "--semantics", "deterministic")
    assert planned.exit_code == 0
    _warned(planned.output, typo)


@pytest.mark.parametrize(
    "args",
    [
        ["export", "-o", "{tmp}/typo.pddl"],
        ["show", "-o", "{tmp}/typo.png", "--dpi", "30"],
        ["evaluate", "{plan}", "--rollouts", "1", "--workers", "1"],
        ["repair", "--plan", "{plan}", "--particles", "1", "--workers", "1"],
    ],
    ids=lambda args: args[0],
)
def test_every_command_that_loads_a_problem_reports_its_warnings(typo, tmp_path, args):
    plan = tmp_path / "plan.json"
    plan.write_text(
        json.dumps(
            {
                "format": "arrange-up-plan/1",
                "status": "solved",
                "actions": [{"type": "place", "object": "A", "pose": [9.5, 0.5, 0]}],
            }
        )
    )
    filled = [a.replace("{tmp}", str(tmp_path)).replace("{plan}", str(plan)) for a in args]
    result = run(filled[0], str(typo), *filled[1:])
    assert result.exit_code in (0, 1), result.output
    _warned(result.output, typo)


def test_a_goal_that_sticks_out_of_the_table_is_warned_about(tmp_path):
    path = tmp_path / "edge.yaml"
    path.write_text(TYPO.replace("tolerence", "tolerance").replace("9.5, 0.5", "9.7, 0.5"))
    result = run("check", str(path))
    assert result.exit_code == 0
    assert f"{path}:8:14: warning: goal.poses.A: at its goal pose A spans x 9.2..10.2" in (
        result.output
    )


def test_a_plan_of_another_problem_under_another_controller_is_warned_of_both(tmp_path):
    # blocks-1's plan (made under the default, compliant, controller) given a servo blocks-2:
    # two mismatches, each its own warning in the words it has alone, neither hiding the other.
    plan = tmp_path / "b1.json"
    planned = run("plan", "blocks-1", "--semantics", "deterministic", "-o", str(plan))
    assert planned.exit_code == 0, planned.output
    problem = tmp_path / "blocks-2-servo.yaml"
    text = (REPOSITORY / "domains" / "blocks-2.yaml").read_text()
    problem.write_text(text + "controller: {kind: servo}\n")
    result = run("evaluate", str(problem), str(plan), "--rollouts", "1", "--workers", "1")
    assert result.exit_code == 0, result.output
    recorded = json.loads(plan.read_text())["problem"]["hash"]
    other, controller = [line for line in result.stderr.splitlines() if "warning" in line]
    assert other.startswith(
        f"arrange-up: warning: {plan}: it was planned for problem 'blocks-1' with other content "
        f"than 'blocks-2' ({recorded} vs sha256:"
    )
    assert other.endswith("); using it anyway")
    assert controller == (
        f"arrange-up: warning: {plan}: it was planned under the compliant controller; problem "
        "'blocks-2' uses the servo one; using it anyway"
    )


# -- check ---------------------------------------------------------------------------------
def test_check_accepts_shipped_names_like_every_other_command():
    result = run("check", "blocks-1", "tz-mating.pddl")
    assert result.exit_code == 0, result.output
    assert "ok: blocks-1" in result.output and "ok: tz-mating" in result.output


def test_check_is_clean_on_the_shipped_problems():
    # every YAML problem and its PDDL twin share a name: that is not a clash
    files = sorted(str(p) for p in (REPOSITORY / "domains").iterdir())
    result = run("check", *files)
    assert result.exit_code == 0, result.output
    assert "error" not in result.output and "warning" not in result.output
    assert result.output.count(": ok: ") == len(files)


def test_check_still_refuses_two_problems_of_one_name_in_a_folder(tmp_path):
    text = (REPOSITORY / "domains" / "blocks-1.yaml").read_text()
    (tmp_path / "one.yaml").write_text(text)
    (tmp_path / "two.yaml").write_text(text)
    result = run("check", str(tmp_path / "one.yaml"), str(tmp_path / "two.yaml"))
    assert result.exit_code == 2
    assert "problem name 'blocks-1' is already used by" in result.output
    # at the name's place, as every diagnostic of check is
    line = next(n for n, t in enumerate(text.splitlines(), 1) if t.startswith("name:"))
    assert f"two.yaml:{line}:7: error: name: problem name" in result.output


def test_a_pddl_name_clash_is_reported_at_the_name_not_at_a_comment(tmp_path):
    text = (REPOSITORY / "domains" / "blocks-1.pddl").read_text()
    (tmp_path / "one.pddl").write_text(text)
    decoy = "; an old copy said (problem decoy)\n"
    (tmp_path / "two.pddl").write_text(decoy + text)
    result = run("check", str(tmp_path / "one.pddl"), str(tmp_path / "two.pddl"))
    assert result.exit_code == 2
    lines = (decoy + text).splitlines()
    line, column = next(
        (n, t.lower().index("(problem") + len("(problem ") + 1)
        for n, t in enumerate(lines, 1)
        if "(problem" in t.lower() and not t.startswith(";")
    )
    assert f"two.pddl:{line}:{column}: error: name: problem name 'blocks-1'" in result.output


def test_check_reports_a_folder_or_a_missing_file_and_checks_the_rest(tmp_path):
    missing = tmp_path / "missing.yaml"
    result = run("check", str(tmp_path), "blocks-1", str(missing), "blocks-2")
    assert result.exit_code == 2
    assert f"{tmp_path}: error: " in result.output and "is a directory" in result.output
    assert f"{missing}: error: " in result.output
    assert "ok: blocks-1" in result.output and "ok: blocks-2" in result.output
    assert "2 of 4 file(s) failed" in result.output


# -- show ------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("suffix", "magic"), [(".svg", b"<?xml"), (".pdf", b"%PDF"), (".png", b"\x89PNG")]
)
def test_show_writes_the_format_its_output_is_named_after(tmp_path, suffix, magic):
    output = tmp_path / f"blocks-1{suffix}"
    result = run("show", "blocks-1", "-o", str(output), "--dpi", "30")
    assert result.exit_code == 0, result.output
    assert output.read_bytes().startswith(magic)


# -- plan files ------------------------------------------------------------------------------
def test_a_plan_file_respects_the_umask(tmp_path):
    output = tmp_path / "plan.json"
    previous = os.umask(0o027)
    try:
        result = run("plan", "blocks-1", "--semantics", "deterministic", "-o", str(output))
    finally:
        os.umask(previous)
    assert result.exit_code == 0, result.output
    assert stat.S_IMODE(output.stat().st_mode) == 0o640


def test_an_exhausted_search_says_so_and_why_in_text_and_json(tmp_path):
    path = tmp_path / "obstacle.yaml"
    path.write_text(text("obstacle"))
    args = ("plan", str(path), "--particles", "5", "--workers", "1")
    shown = run(*args)
    assert shown.exit_code == 1
    status, why = shown.output.splitlines()
    assert status.startswith("obstacle: exhausted (particles, 5 particles, seed 0)")
    assert why.startswith("exhausted after 3 nodes: 0 candidates refused by the semantics")
    assert why.endswith("by the ordering filter; the best belief still misses A in x")
    assert "pruned as dominated" in why and "unsolvable" not in shown.output
    summary = json.loads(run(*args, "--json", "-o", str(tmp_path / "p.json")).stdout)
    assert summary["status"] == "exhausted" and summary["reason"] == why
    assert json.loads((tmp_path / "p.json").read_text())["status"] == "exhausted"


def test_a_goal_part_larger_than_the_table_is_unsolvable(tmp_path):
    path = tmp_path / "big.yaml"
    path.write_text(
        textwrap.dedent(
            """\
            name: big
            table: {size: [3, 2]}
            objects:
              A: {kind: part, shape: {box: [4, 3]}}
              paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
            goal:
              tolerance: [0.2, 0.2, 15]
              poses: {A: [1.5, 1, 0]}
            """
        )
    )
    shown = run("plan", str(path), "--semantics", "deterministic")
    assert shown.exit_code == 1
    assert "big: unsolvable (deterministic" in shown.output
    assert "part A (4 x 3 in) fits the 3 x 2 in table at no angle: no plan exists" in shown.output
    summary = json.loads(run("plan", str(path), "--semantics", "deterministic", "--json").stdout)
    assert summary["status"] == "unsolvable" and summary["plan_length"] is None
    # check says so too, as a warning: the file is valid, but no plan exists
    checked = run("check", str(path))
    assert checked.exit_code == 0
    assert (
        f"{path}: warning: goal.poses.A: part A (4 x 3 in) fits the 3 x 2 in table at no angle: "
        "no plan exists (plan answers unsolvable)"
    ) in checked.stderr
    assert "warning" not in run("check", "blocks-4").stderr  # a solvable problem: no warning
