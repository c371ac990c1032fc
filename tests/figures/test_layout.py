"""Layout of the figures, measured with the renderer: a long storyboard's title clear of its
first row's panel titles and its legend clear of the panels; a relative-goal picture's note
box clear of its legend; goal regions clipped to the table."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest
from catalogue import servo, tiny

from arrange_up.figures import storyboard
from arrange_up.io.domains import load
from arrange_up.io.yaml_problem import load_problem_text
from arrange_up.model.world import Place, Push

EAST, SOUTH = -math.pi / 2, -math.pi
#: Twenty actions of one-block (a place, then pushes right and down): 21 panels, six rows.
RIGHT = Push("paddle", (3.377683, 1.322212, EAST), 0.5473)
DOWN = Push("paddle", (3.677788, 1.622523, SOUTH), 0.5475)
LONG_PLAN = (Place("A", (4.088, 0.912, 0.0)), *(RIGHT, DOWN) * 9, RIGHT)

#: A goal region that reaches past the table's top edge (B may take any angle near the edge).
NEAR_EDGE = """
name: near-edge
units: {length: cm, angle: deg}
table: {size: [30, 20], walls: [left, bottom, top]}
objects:
  A: {kind: part, shape: {box: [2.54, 2.54]}}
  B: {kind: part, shape: {polygon: [[0, 0], [5, 0], [5, 2], [2, 2], [2, 5], [0, 5]]}}
  paddle: {kind: manipulator, shape: {box: [6, 0.4]}}
initial:
  A: {pose: [5, 5, 0], uncertainty: [0.5, 0.5, 15]}
goal:
  tolerance: [0.5, 0.5]
  poses:
    A: [25, 4, 0]
    B: [8, 17.5, 45]
"""


def _renderer(fig: Any) -> Any:
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    return canvas.get_renderer()


def _overlap(a: Any, b: Any) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


@pytest.fixture(scope="module")
def long_storyboard(tmp_path_factory: pytest.TempPathFactory) -> Any:
    """The figure of a 21-panel storyboard, as saved (kept open for measuring)."""
    kept: dict[str, Any] = {}

    def keep(fig: Any, output: Path, **options: Any) -> Path:
        kept["figure"] = fig
        return Path(output)

    original = storyboard.save_figure
    storyboard.save_figure = keep  # type: ignore[assignment]
    try:
        problem = servo(tiny("one-block"))
        output = tmp_path_factory.mktemp("story") / "long.png"
        storyboard.draw_storyboard(problem, LONG_PLAN, output, rollouts=1)
    finally:
        storyboard.save_figure = original  # type: ignore[assignment]
    return kept["figure"]


def test_long_storyboard_title_clears_the_first_row(long_storyboard: Any) -> None:
    fig = long_storyboard
    renderer = _renderer(fig)
    titles = [ax.title.get_window_extent(renderer) for ax in fig.axes if ax.get_title()]
    assert len(titles) == len(LONG_PLAN) + 1
    heading = fig._suptitle.get_window_extent(renderer)
    assert heading.y0 > max(box.y1 for box in titles)
    assert heading.y1 <= fig.bbox.y1


def test_long_storyboard_legend_clears_the_panels(long_storyboard: Any) -> None:
    fig = long_storyboard
    renderer = _renderer(fig)
    (legend,) = fig.legends
    box = legend.get_window_extent(renderer)
    assert box.y0 >= fig.bbox.y0
    panels = [ax.get_tightbbox(renderer) for ax in fig.axes if ax.axison]
    assert not any(_overlap(box, panel) for panel in panels)


def test_storyboard_panel_titles_give_angles_with_units(long_storyboard: Any) -> None:
    titles = [ax.get_title() for ax in long_storyboard.axes if ax.get_title()]
    assert titles[1] == "1. place A at (4.09, 0.91, 0 deg)"


def test_relative_goal_picture_note_box_clears_the_legend() -> None:
    from arrange_up.figures.backend import pyplot
    from arrange_up.figures.render import problem_figure

    fig = problem_figure(load("tz-mating"))
    try:
        renderer = _renderer(fig)
        goal_axes = fig.axes[1]
        legend = goal_axes.get_legend()
        (note,) = [t for t in goal_axes.texts if "goal tolerance" in t.get_text()]
        legend_box = legend.get_window_extent(renderer)
        note_box = note.get_bbox_patch().get_window_extent(renderer)
        assert not _overlap(legend_box, note_box)
        assert note_box.y1 <= legend_box.y0
    finally:
        pyplot().close(fig)


def test_goal_regions_are_clipped_to_the_table() -> None:
    from arrange_up.figures.backend import pyplot
    from arrange_up.figures.render import draw_goal, draw_table

    problem = load_problem_text(NEAR_EDGE, "near-edge.yaml")
    fig, ax = pyplot().subplots()
    try:
        draw_table(ax, problem)
        regions = [a for a in draw_goal(ax, problem) if hasattr(a, "get_path")]
        ax.set_xlim(-2, 32)
        ax.set_ylim(-2, 24)
        renderer = _renderer(fig)
        (tx0, ty0), (tx1, ty1) = ax.transData.transform([(0.0, 0.0), problem.table.size])
        # the unclipped regions reach past the top wall, so the clipping is what keeps them in
        assert max(a.get_window_extent(renderer).y1 for a in regions) > ty1 + 1
        for artist in regions:
            assert artist.get_clip_on()
            clip = artist.get_clip_box()
            assert clip.x0 >= tx0 - 0.5 and clip.x1 <= tx1 + 0.5
            assert clip.y0 >= ty0 - 0.5 and clip.y1 <= ty1 + 0.5
    finally:
        pyplot().close(fig)
