"""Tests of ``arrange_up.figures.animation`` and ``scene``: the frames of a plan's animation
(interpolated scenes, a GIF with one frame each), the writer check, and the layers, legend and
axes every storyboard panel and frame shares."""

from __future__ import annotations

import math

import pytest
from catalogue import tiny
from matplotlib import animation as mpl_animation
from matplotlib.colors import to_rgba
from PIL import Image, ImageChops

from arrange_up.figures import render
from arrange_up.figures.animation import (
    WriterUnavailableError,
    animate_plan,
    check_writer,
    frame_plan,
)
from arrange_up.figures.backend import pyplot
from arrange_up.figures.scene import (
    GOAL_COLOR,
    draw_goal_outlines,
    has_shadows,
    legend_handles,
    prediction_label,
    scene_at,
    style_axes,
)
from arrange_up.figures.storyboard import storyboard_data
from arrange_up.model.world import Place, Push

EAST, SOUTH = -math.pi / 2, -math.pi
#: A plan of one-block (the deterministic planner's): place, push right, push down.
PLAN = (
    Place("A", (4.088, 0.912, 0.0)),
    Push("paddle", (3.377683, 1.322212, EAST), 0.5473),
    Push("paddle", (3.677788, 1.622523, SOUTH), 0.5475),
)


def test_frame_plan_holds_the_start_and_the_end_around_the_actions():
    assert frame_plan(2, 3, 2) == [
        (0, 1.0), (0, 1.0),
        (1, 1 / 3), (1, 2 / 3), (1, 1.0),
        (2, 1 / 3), (2, 2 / 3), (2, 1.0),
        (2, 1.0),
    ]  # fmt: skip
    assert frame_plan(0, 5, 3) == [(0, 1.0)] * 3


def test_scenes_interpolate_between_the_states_before_and_after_an_action():
    problem = tiny("one-block")
    data = storyboard_data(problem, PLAN, rollouts=2, seed=1)
    start = scene_at(data, 0)
    assert start.nominal == () and start.shadows == ()
    # A place fades the part in at its placed pose.
    placing = scene_at(data, 1, 0.25)
    assert [(name, alpha) for name, _, alpha in placing.nominal] == [("A", 0.25)]
    # A push moves it: halfway, the pose is the mean of the poses before and after.
    before, after = data["nominal"][1].pose("A"), data["nominal"][2].pose("A")
    (name, halfway, alpha), = scene_at(data, 2, 0.5).nominal  # fmt: skip
    assert name == "A" and alpha == 1.0
    assert halfway[:2] == pytest.approx(((before[0] + after[0]) / 2, (before[1] + after[1]) / 2))
    assert scene_at(data, 2, 1.0).nominal == (("A", after, 1.0),)
    # Each rollout is in every scene, at its own state.
    assert len(scene_at(data, 3).rollouts) == 2


def test_a_failed_rollout_stays_at_its_last_state_marked_failed():
    problem = tiny("one-block")
    twice = (PLAN[0], PLAN[0])  # placing A again while it is on the table fails
    data = storyboard_data(problem, twice, rollouts=1)
    scene = scene_at(data, 2, 0.5)
    assert scene.nominal_failed
    assert scene.nominal == tuple((n, p, 1.0) for n, p in data["nominal"][1].poses)
    ((placed, failed),) = scene.rollouts
    assert failed and [name for name, _, _ in placed] == ["A"]


def test_shadows_and_their_legend_entry_only_where_the_prediction_has_some():
    problem = tiny("one-block")
    deterministic = storyboard_data(problem, PLAN[:1], rollouts=0)
    particles = storyboard_data(
        problem, PLAN[:1], rollouts=0, semantics="particles", particles=5, plan_seed=1
    )
    assert not has_shadows(deterministic) and has_shadows(particles)
    labels = [h.get_label() for h in legend_handles(problem, PLAN, rollouts=3, shadows=False)]
    assert labels[0].startswith("goal") and "3 noisy rollouts" in labels
    assert "commanded place" in labels and "manipulator, push" in labels
    assert not any("shadow" in label for label in labels)
    with_shadows = legend_handles(problem, PLAN[1:], rollouts=0, shadows=True)
    labels = [h.get_label() for h in with_shadows]
    assert "predicted belief shadow" in labels and "commanded place" not in labels
    assert not any("rollout" in label for label in labels)


def test_titles_say_when_the_shadows_are_a_replay_of_another_kind_of_plan():
    assert prediction_label("deterministic", 1, None) == "predicted shadows (deterministic)"
    assert prediction_label("particles", 25, "particles") == (
        "predicted shadows (particles, 25 particles)"
    )
    label = prediction_label("particles", 150, "fixtures")
    assert label.startswith("fixtures plan") and "150 particles" in label
    assert "deterministic" not in label


def test_axes_are_ticked_and_labelled_in_the_problems_unit():
    plt = pyplot()
    fig, ax = plt.subplots()
    try:
        style_axes(ax, tiny("millimetres"))
        assert ax.get_xlabel() == "x (mm)" and ax.get_ylabel() == "y (mm)"
        labels = [t.get_text() for t in ax.get_xticklabels()]
        # Round millimetre values, placed at their position in inches.
        assert labels == ["0", "40", "80", "120"]
        assert list(ax.get_xticks()) == pytest.approx([0, 40 / 25.4, 80 / 25.4, 120 / 25.4])
        style_axes(ax, tiny("one-block"))
        assert ax.get_xlabel() == "x (in)"
    finally:
        plt.close(fig)


def test_animate_plan_writes_a_gif_with_a_frame_each_that_move(tmp_path):
    plt = pyplot()
    before = set(plt.get_fignums())
    out = animate_plan(
        tiny("one-block"),
        PLAN,
        tmp_path / "movie" / "plan.gif",
        rollouts=2,
        frames_per_action=2,
        hold=1,
        dpi=30,
    )
    assert out == tmp_path / "movie" / "plan.gif"
    with Image.open(out) as gif:
        assert gif.format == "GIF" and gif.n_frames == len(frame_plan(3, 2, 1)) == 7
        gif.seek(0)
        first = gif.convert("RGB")
        gif.seek(4)  # halfway through the second action: the paddle has moved
        middle = gif.convert("RGB")
        assert ImageChops.difference(first, middle).getbbox() is not None
    assert set(plt.get_fignums()) == before


def test_writers_by_suffix_and_a_clear_error_without_ffmpeg(tmp_path, monkeypatch):
    assert check_writer(tmp_path / "a.GIF") == "pillow"
    with pytest.raises(WriterUnavailableError, match=r"unknown animation format '\.avi'"):
        check_writer(tmp_path / "a.avi")
    monkeypatch.setattr(mpl_animation.writers, "is_available", lambda name: name != "ffmpeg")
    with pytest.raises(WriterUnavailableError, match="needs the ffmpeg program on the PATH"):
        animate_plan(tiny("one-block"), PLAN, tmp_path / "a.mp4", rollouts=0)
    assert not (tmp_path / "a.mp4").exists()
    monkeypatch.setattr(mpl_animation.writers, "is_available", lambda name: True)
    assert check_writer(tmp_path / "a.mp4") == "ffmpeg"


def test_bad_frame_options_are_refused(tmp_path):
    with pytest.raises(ValueError, match="fps must be positive"):
        animate_plan(tiny("one-block"), PLAN, tmp_path / "a.gif", rollouts=0, fps=0)


def test_goals_are_solid_green_outlines_unlike_the_dashed_shadows():
    problem = tiny("one-block")
    plt = pyplot()
    fig, ax = plt.subplots()
    try:
        goal = [a for a in draw_goal_outlines(ax, problem) if hasattr(a, "get_edgecolor")]
        assert goal and all(a.get_linestyle() == "-" for a in goal)
        assert all(a.get_edgecolor() == to_rgba(GOAL_COLOR) for a in goal)
        shadow = render.draw_shadows(ax, problem.object("A"), (2, 1, 0), (0.2, 0.2, 0.1))
        assert shadow[-1].get_linestyle() == "--"
    finally:
        plt.close(fig)
