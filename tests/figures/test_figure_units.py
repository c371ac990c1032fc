"""The problem picture and the storyboard titles speak the problem file's own units: axes
labelled and ticked in its length unit, notes in its length and angle units, place angles in
radians with 2 decimals (whole degrees as before)."""

from __future__ import annotations

import math
from pathlib import Path

from click.testing import CliRunner

from arrange_up.cli import main
from arrange_up.figures.backend import pyplot
from arrange_up.figures.render import problem_figure
from arrange_up.figures.scene import describe
from arrange_up.io.domains import load
from arrange_up.io.yaml_problem import load_problem
from arrange_up.model.world import Place

CM_RAD = """
name: cm-rad
units: {length: cm, angle: rad}
table: {size: [30, 20]}
objects:
  A: {kind: part, shape: {box: [3, 3]}}
  paddle: {kind: manipulator, shape: {box: [6, 0.4]}}
initial: {}
goal:
  tolerance: [1, 1, 0.3]
  poses:
    A: [20, 10, 1.57]
"""

CM_RELATIVE = """
name: cm-relative
units: {length: cm, angle: rad}
table: {size: [30, 20]}
objects:
  R: {kind: part, shape: {box: [3, 3]}}
  S: {kind: part, shape: {box: [3, 3]}}
initial:
  R: {pose: [5, 5, 0]}
  S: {pose: [20, 10, 0]}
goal:
  tolerance: [1, 1]
  relative: {reference: R, poses: {S: [3, 0, 0]}}
"""


def _problem(tmp_path: Path, text: str, name: str):
    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    return load_problem(path)


def _axes_text(fig) -> list[tuple[str, str, list[str], list[str]]]:
    fig.canvas.draw()
    return [
        (
            ax.get_xlabel(),
            ax.get_ylabel(),
            [t.get_text() for t in ax.get_xticklabels()],
            [t.get_text() for t in ax.get_yticklabels()],
        )
        for ax in fig.axes
    ]


def _notes(fig) -> str:
    return "\n".join(t.get_text() for ax in fig.axes for t in ax.texts)


def test_a_cm_rad_problem_is_drawn_with_cm_axes_and_cm_rad_notes(tmp_path):
    problem = _problem(tmp_path, CM_RAD, "cm-rad")
    fig = problem_figure(problem)
    try:
        ((xlabel, ylabel, xticks, yticks),) = _axes_text(fig)
        assert (xlabel, ylabel) == ("x (cm)", "y (cm)")
        # round centimetre values (the table is 30 x 20 cm, 11.8 x 7.9 in)
        assert {"0", "10", "20", "30"} <= set(xticks)
        assert {"0", "10", "20"} <= set(yticks)
        notes = _notes(fig)
        assert "paddle (6 x 0.4 cm)" in notes
        assert "goal tolerance: +-1 cm, +-1 cm, +-0.3 rad" in notes
        assert " in" not in notes and "deg" not in notes
    finally:
        pyplot().close(fig)


def test_a_relative_goal_panel_is_labelled_in_the_problems_unit(tmp_path):
    problem = _problem(tmp_path, CM_RELATIVE, "cm-relative")
    fig = problem_figure(problem)
    try:
        labels = [(x, y) for x, y, _, _ in _axes_text(fig)]
        assert labels == [("x (cm)", "y (cm)"), ("x in R's frame (cm)", "y in R's frame (cm)")]
    finally:
        pyplot().close(fig)


def test_an_inch_degree_problem_is_drawn_as_before():
    fig = problem_figure(load("blocks-4"))
    try:
        ((xlabel, ylabel, xticks, _),) = _axes_text(fig)
        assert (xlabel, ylabel) == ("x (in)", "y (in)")
        assert "10" in xticks
        assert "goal tolerance: +-0.2 in, +-0.2 in, +-15 deg" in _notes(fig)
    finally:
        pyplot().close(fig)


def test_place_titles_print_radians_with_two_decimals_and_degrees_whole(tmp_path):
    cm_rad = _problem(tmp_path, CM_RAD, "cm-rad")
    pose = cm_rad.units.pose_in((20.0, 10.0, 1.57))
    assert describe(Place("A", pose), cm_rad) == "place A at (20.00, 10.00, 1.57 rad)"
    inch_deg = load("blocks-4")
    place = Place("A", (4.0, 1.0, math.radians(90.4)))
    assert describe(place, inch_deg) == "place A at (4.00, 1.00, 90 deg)"
    # a small negative angle reads as zero, not "-0"
    assert describe(Place("A", (4.0, 1.0, math.radians(-0.02))), inch_deg).endswith(", 0 deg)")
    assert describe(Place("A", pose[:2] + (-0.001,)), cm_rad).endswith(", 0.00 rad)")


def test_show_of_a_cm_rad_problem_writes_its_picture(tmp_path):
    path = tmp_path / "cm-rad.yaml"
    path.write_text(CM_RAD)
    result = CliRunner().invoke(main, ["show", str(path), "-o", str(tmp_path / "p.png")])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "p.png").stat().st_size > 10_000
