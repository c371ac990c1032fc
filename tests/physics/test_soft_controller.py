"""``arrange-up check`` warns when the compliant controller is too soft for the parts (a push's
nominal stall is longer than the table's shorter side, so no push can make up for it), as it
warns when it is too stiff for a manipulator: densities in grams where the gains expect
kilograms check "ok" but every push stalls far short. The shipped problems do not warn."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from click.testing import CliRunner

from arrange_up.cli import main
from arrange_up.io.domains import load
from arrange_up.physics.stall import soft_parts, stall_per_area

REPOSITORY = Path(__file__).resolve().parents[2]


def _grams(tmp_path: Path) -> Path:
    """tt-mating with part densities of 2-3 g/cm² written per in² (x 2.54²): a thousand times
    the kilogram file's."""
    text = (REPOSITORY / "domains" / "tt-mating.yaml").read_text(encoding="utf-8")
    text, count = re.subn(r"part_density: \[[^\]]*\]", "part_density: [12.9, 19.4]", text)
    assert count == 1
    path = tmp_path / "grams.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_check_warns_of_a_controller_too_soft_for_gram_scale_parts(tmp_path: Path) -> None:
    path = _grams(tmp_path)
    result = CliRunner().invoke(main, ["check", str(path)])
    assert result.exit_code == 0, result.output  # a warning, not an error
    warnings = [line for line in result.output.splitlines() if "too soft for part" in line]
    assert len(warnings) == 2, result.output  # both tees
    assert warnings[0].startswith(f"{path}: warning: controller: ")
    assert "more than the table's 12 in" in warnings[0]


def test_soft_parts_measure_the_stall_and_the_kp_that_ends_it(tmp_path: Path) -> None:
    problem = load(_grams(tmp_path))
    found = soft_parts(problem)
    assert [soft.name for soft in found] == [part.name for part in problem.parts]
    for soft, part in zip(found, problem.parts, strict=True):
        assert soft.stall == pytest.approx(stall_per_area(problem) * part.shape.area)
        assert soft.stall > soft.reach == 12.0
        # at kp_min the stall is exactly the reach
        assert soft.stall * problem.controller.kp / soft.kp_min == pytest.approx(soft.reach)


@pytest.mark.parametrize(
    "name", ["blocks-1", "blocks-9", "create-a-t", "down-push", "tt-mating-noisy", "tz-mating"]
)
def test_shipped_problems_do_not_warn(name: str) -> None:
    assert soft_parts(load(REPOSITORY / "domains" / f"{name}.yaml")) == []


def test_check_of_a_shipped_problem_prints_no_soft_warning() -> None:
    result = CliRunner().invoke(main, ["check", str(REPOSITORY / "domains" / "tt-mating.yaml")])
    assert result.exit_code == 0, result.output
    assert "too soft" not in result.output
