"""`arrange-up plan --model`: a CBST model by name or card path, refused cleanly otherwise."""

from __future__ import annotations

import json
from pathlib import Path

from click.testing import CliRunner

from arrange_up.cli import main
from arrange_up.io.resources import shipped_dir

CARD = shipped_dir("semantics", "the shipped semantics") / "cbst" / "servo.json"


def test_a_model_card_plans_and_is_recorded_in_the_plan_file(tmp_path: Path) -> None:
    out = tmp_path / "b2.json"
    # the servo's model plans a problem of the servo
    problem = tmp_path / "blocks-2-servo.yaml"
    source = shipped_dir("domains", "the shipped domains") / "blocks-2.yaml"
    problem.write_text(source.read_text() + "controller: {kind: servo}\n")
    args = ["plan", str(problem), "--semantics", "cbst", "--model", str(CARD), "-o", str(out)]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 0, result.output
    document = json.loads(out.read_text())
    assert document["status"] == "solved" and document["model"] == str(CARD)


def test_a_model_for_another_semantics_or_a_missing_one_exits_2(tmp_path: Path) -> None:
    runner = CliRunner()
    particles = runner.invoke(main, ["plan", "blocks-1", "--particles", "3", "--model", "default"])
    assert particles.exit_code == 2 and "--model default:" in particles.output
    assert "Traceback" not in particles.output
    missing = runner.invoke(
        main, ["plan", "blocks-1", "--semantics", "cbst", "--model", str(tmp_path / "no.json")]
    )
    assert missing.exit_code == 2 and "no.json" in missing.output
