"""Generated problems (arrange_up.io.generate and ``arrange-up generate``): every family writes
valid files for 2 to 20 parts, the same arguments the same bytes, small ones plan, and bad
input is one line and exit 2."""

from __future__ import annotations

import pytest
from click.testing import CliRunner

from arrange_up.cli import main
from arrange_up.io.generate import (
    FAMILIES,
    MAX_PARTS,
    Noise,
    generate_problem,
    pack_rows,
    part_names,
    staircase_rows,
)
from arrange_up.io.validation import goal_overlaps
from arrange_up.io.yaml_problem import check_problem_text, load_problem_text
from arrange_up.planning.fitting import unfit_parts
from arrange_up.planning.planner import plan


@pytest.mark.parametrize("family", FAMILIES)
def test_every_family_is_valid_from_2_to_20_parts(family):
    for parts in range(2, 21):
        for seed in (0, 1):
            text = generate_problem(family, parts, seed)
            problem, diagnostics = check_problem_text(text, f"{family}-{parts}")
            assert problem is not None and not diagnostics, [str(d) for d in diagnostics]
            assert len(problem.parts) == parts
            assert problem.name == f"{family}-{parts}-s{seed}"
            assert not unfit_parts(problem) and not goal_overlaps(problem)
            assert problem.goal.is_relative == (family == "relative")
            assert not problem.initial  # every part starts off the table


@pytest.mark.parametrize("family", FAMILIES)
def test_the_same_arguments_give_the_same_bytes_and_seeds_vary_the_file(family):
    assert generate_problem(family, 6, 3) == generate_problem(family, 6, 3)
    texts = {generate_problem(family, 6, seed) for seed in range(8)}
    assert len(texts) == 8  # the name differs at least
    layouts = {t.split("objects:")[1] for t in texts}
    assert len(layouts) > 1  # and what the seed chooses


def test_the_families_grow_their_tables_with_the_parts():
    for family in FAMILIES:
        small = load_problem_text(generate_problem(family, 2)).table.size
        large = load_problem_text(generate_problem(family, 20)).table.size
        assert small[0] >= 10 and small[1] >= 5
        assert large[0] * large[1] > small[0] * small[1]


def test_row_shapes():
    assert staircase_rows(9) == [4, 3, 2]
    assert staircase_rows(7) == [4, 3]
    assert sum(staircase_rows(20)) == 20
    assert pack_rows(4) == [2, 2] and pack_rows(9) == [3, 3, 3] and pack_rows(16) == [6, 6, 4]
    assert part_names(28)[-3:] == ["Z", "AA", "AB"]


def test_noise_options_are_written():
    text = generate_problem("row", 3, noise=Noise(place=(0.3, 0.3, 20), friction=(0.2, 0.8)))
    problem = load_problem_text(text)
    assert "place: [0.3, 0.3, 20]" in text and "friction: [0.2, 0.8]" in text
    assert problem.uncertainty.friction == (0.2, 0.8)


@pytest.mark.parametrize(
    "args",
    [(), ("unknown-family", 3, 0), ("row", 0, 0), ("row", MAX_PARTS + 1, 0), ("row", 3, -1)],
)
def test_the_library_refuses_bad_arguments(args):
    with pytest.raises((ValueError, TypeError)):
        generate_problem(*args)
    with pytest.raises(ValueError):
        generate_problem("relative", 1)


@pytest.mark.parametrize("family", FAMILIES)
@pytest.mark.parametrize("parts", [2, 3])
def test_small_generated_problems_plan(family, parts):
    problem = load_problem_text(generate_problem(family, parts, 0))
    result = plan(problem, semantics="deterministic", workers=1, timeout=120)
    assert result.solved, result.reason


def test_the_command_writes_a_file_that_checks(tmp_path):
    out = tmp_path / "staircase.yaml"
    args = ["generate", "staircase", "--parts", "5", "--seed", "2", "-o", str(out)]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 0, result.output
    assert out.read_text(encoding="utf-8") == generate_problem("staircase", 5, 2)
    checked = CliRunner().invoke(main, ["check", str(out)])
    assert checked.exit_code == 0 and "ok: staircase-5-s2" in checked.output


def test_the_command_prints_without_output_and_takes_noise_options():
    args = ["generate", "mixed", "-n", "4", "--place-uncertainty", "0.3,0.3,20"]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 0
    noise = Noise(place=(0.3, 0.3, 20))
    assert result.output == generate_problem("mixed", 4, 0, noise=noise)


def test_the_help_lists_every_family():
    result = CliRunner().invoke(main, ["generate", "--help"])
    assert result.exit_code == 0
    for family, line in FAMILIES.items():
        assert f"{family} " in result.output and line.split()[0] in result.output


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["generate", "spiral", "-n", "3"], "FAMILY"),
        (["generate", "row", "-n", "0"], "--parts"),
        (["generate", "row", "-n", str(MAX_PARTS + 1)], "--parts"),
        (["generate", "relative", "-n", "1"], "--parts"),
        (["generate", "row", "-n", "3", "-o", "{tmp}/file/x.yaml"], "--output"),
        (["generate", "row", "-n", "3", "--friction", "0.9,0.2"], "friction"),
        (["generate", "row", "-n", "3", "--place-uncertainty", "1,2"], "--place-uncertainty"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(tmp_path, args, fragment):
    (tmp_path / "file").write_text("a file, not a folder\n")
    filled = [a.replace("{tmp}", str(tmp_path)) for a in args]
    result = CliRunner().invoke(main, filled)
    assert result.exit_code == 2
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("arrange-up: generate: "), result.output
    assert fragment in lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]
