"""Tests of the problem drawing (``arrange_up.figures.render``): files are written and layers
draw."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pytest

from arrange_up.io.domains import load
from arrange_up.io.yaml_problem import load_problem_text
from arrange_up.model.problem import ArrangementProblem

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"

MIXED = """
name: mixed
description: Centimetres, an obstacle, a fixture on the table and an any-angle goal.
units: {length: cm, angle: deg}
table: {size: [30, 20], walls: [left, bottom]}
objects:
  A: {kind: part, shape: {box: [2.54, 2.54]}}
  B: {kind: part, shape: {polygon: [[0, 0], [5, 0], [5, 2], [2, 2], [2, 5], [0, 5]]}}
  paddle: {kind: manipulator, shape: {box: [6, 0.4]}}
  bar: {kind: fixture, shape: {box: [5, 1.2]}}
  post: {kind: obstacle, shape: {box: [2, 2]}, pose: [15, 10, 0]}
initial:
  A: {pose: [5, 5, 0], uncertainty: [0.5, 0.5, 15]}
  bar: {pose: [24, 15, 90]}
goal:
  tolerance: [0.5, 0.5]
  poses:
    A: [25, 4, 0]
    B: [8, 14, 45]
"""


@pytest.fixture(scope="module")
def mixed() -> ArrangementProblem:
    return load_problem_text(MIXED, "mixed.yaml")


def _assert_png(path: Path) -> None:
    assert path.is_file()
    data = path.read_bytes()
    assert data.startswith(PNG_SIGNATURE)
    assert len(data) > 10_000


def test_draw_absolute_goal_problem(tmp_path: Path) -> None:
    from arrange_up.figures.render import draw_problem

    out = draw_problem(load("blocks-4"), tmp_path / "blocks-4.png", dpi=60)
    assert out == tmp_path / "blocks-4.png"
    _assert_png(out)


def test_draw_relative_goal_problem(tmp_path: Path) -> None:
    from arrange_up.figures.render import draw_problem

    out = draw_problem(load("tz-mating"), tmp_path / "sub" / "tz.png", title="TZ", dpi=60)
    _assert_png(out)


def test_draw_obstacles_fixtures_units_and_any_angle(
    tmp_path: Path, mixed: ArrangementProblem
) -> None:
    from arrange_up.figures.render import draw_problem

    _assert_png(draw_problem(mixed, str(tmp_path / "mixed.png"), dpi=60))


def test_layers_draw_on_a_given_axes(mixed: ArrangementProblem) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from arrange_up.figures.render import (
        draw_goal,
        draw_initial,
        draw_object,
        draw_shadows,
        draw_table,
        object_color,
    )

    fig, ax = plt.subplots()
    try:
        assert len(draw_table(ax, mixed)) >= 1 + 2 + 2 + 1  # surface, walls, open edges, post
        spec = mixed.object("A")
        pose = (3.0, 2.0, 0.0)
        (patch, text) = draw_object(ax, spec, pose, label="A", color=object_color(mixed, "A"))
        assert patch.get_extents() is not None and text.get_text() == "A"
        assert draw_shadows(ax, spec, pose, (0.0, 0.0, 0.0)) == []
        hull, box = draw_shadows(ax, spec, pose, (0.2, 0.2, math.radians(15)))
        x0, y0 = box.get_xy()
        assert x0 < 3.0 - 0.7 and y0 < 2.0 - 0.7
        assert len(draw_initial(ax, mixed)) >= 2
        assert len(draw_goal(ax, mixed)) >= 2
    finally:
        plt.close(fig)


def test_relative_goal_drawn_around_a_reference_pose() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from arrange_up.figures.render import draw_goal

    problem = load("tt-mating")
    fig, ax = plt.subplots()
    try:
        artists = draw_goal(ax, problem, reference_pose=(6.0, 6.0, math.pi))
        texts = {a.get_text(): a.get_position() for a in artists if hasattr(a, "get_text")}
        assert texts["T1"] == pytest.approx((6.0, 6.0))
        # T2 sits at (1.0, -1.8) in T1's frame; T1 turned by 180 degrees puts it at (5, 7.8)
        x, y = texts["T2"]
        assert x == pytest.approx(5.0) and 7.0 < y < 7.8
        assert ax.get_title() == "relative goal (reference: T1)"
    finally:
        plt.close(fig)


def test_off_table_note_and_tolerance(mixed: ArrangementProblem) -> None:
    from arrange_up.figures.render import goal_tolerance_half_widths, off_table_note

    note = off_table_note(load("blocks-4"))
    assert note.splitlines()[0] == "off table: A, B, C, D"
    assert "paddle (2.5 x 0.15 in)" in note
    assert "off table" not in off_table_note(load("tz-mating"))
    assert "bar" not in off_table_note(mixed)  # the fixture starts on the table
    assert goal_tolerance_half_widths(mixed)[2] == pytest.approx(math.pi)


def test_the_package_and_the_cli_help_do_not_import_matplotlib() -> None:
    # The figure modules import matplotlib at module level; the package and the command line
    # import them only where they draw, so neither `import arrange_up` nor `--help` pays for it.
    code = (
        "import sys, arrange_up, arrange_up.cli as cli\n"
        "from click.testing import CliRunner\n"
        "assert CliRunner().invoke(cli.main, ['--help']).exit_code == 0\n"
        "print('matplotlib' in sys.modules)"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    assert result.stdout.strip() == "False"
