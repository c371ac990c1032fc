"""Animations of a plan's execution: the nominal execution, the predicted belief shadows, the
goal and a cloud of noisy rollouts moving together, action by action, as a GIF or an MP4.

The frames are the storyboard's data (:func:`arrange_up.figures.storyboard.storyboard_data`:
the states before and after each action of the nominal execution and of each rollout, and the
semantics' predicted belief after each action) drawn by :mod:`arrange_up.figures.scene`:
``frames_per_action`` frames per action, interpolated between the state before and after it
(the physics records the state after each action, not the motion during a push; so the
objects are interpolated linearly while the manipulator moves along the commanded push), plus
``hold`` frames of the start and of the end. Each frame is titled with its action; a legend
and axes in the problem's length unit are drawn below and beside the table.

``.gif`` files are written with Pillow (a matplotlib dependency); ``.mp4`` files need the
``ffmpeg`` program on the PATH (:class:`WriterUnavailableError` otherwise).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path

from matplotlib import animation

from arrange_up.figures.backend import pyplot
from arrange_up.figures.scene import (
    describe,
    draw_action,
    draw_scene,
    has_shadows,
    legend_handles,
    prediction_label,
    scene_at,
    style_axes,
)
from arrange_up.figures.storyboard import storyboard_data
from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Action

__all__ = ["FORMATS", "WriterUnavailableError", "animate_plan", "check_writer", "frame_plan"]

#: The animation formats by file suffix, with the matplotlib writer each needs.
FORMATS = {".gif": "pillow", ".mp4": "ffmpeg"}


class WriterUnavailableError(ValueError):
    """The output's format is unknown, or its writer is not installed."""


def check_writer(output: Path) -> str:
    """The matplotlib writer for ``output``'s suffix; raises :class:`WriterUnavailableError`
    for an unknown suffix or a writer that is not available (``.mp4`` without ffmpeg)."""
    suffix = Path(output).suffix.lower()
    if suffix not in FORMATS:
        raise WriterUnavailableError(
            f"{output}: unknown animation format {suffix or '(none)'!r}; "
            f"expected one of {', '.join(FORMATS)}"
        )
    writer = FORMATS[suffix]
    if not animation.writers.is_available(writer):
        need = "the ffmpeg program on the PATH" if writer == "ffmpeg" else f"matplotlib's {writer}"
        raise WriterUnavailableError(
            f"{output}: writing {suffix} needs {need}, which was not found; write a .gif instead"
        )
    return writer


def frame_plan(actions: int, frames_per_action: int, hold: int) -> list[tuple[int, float]]:
    """The (action, fraction) of each frame: ``hold`` frames of the start (action 0), then
    ``frames_per_action`` per action with fractions ``1/f .. 1``, then ``hold - 1`` more of the
    end (which the last action's final frame already shows once)."""
    frames = [(0, 1.0)] * hold
    for k in range(1, actions + 1):
        frames += [(k, i / frames_per_action) for i in range(1, frames_per_action + 1)]
    if actions:
        frames += [(actions, 1.0)] * max(0, hold - 1)
    return frames


def animate_plan(
    problem: ArrangementProblem,
    actions: Sequence[Action],
    output: Path,
    *,
    rollouts: int = 50,
    seed: int = 0,
    semantics: str = "deterministic",
    particles: int = 1,
    plan_seed: int = 0,
    plan_semantics: str | None = None,
    fps: float = 6.0,
    frames_per_action: int = 6,
    hold: int = 4,
    dpi: int = 90,
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Write the animation of a plan's execution to ``output`` (``.gif`` or ``.mp4``; see the
    module docstring) and return its path.

    ``rollouts``, ``seed``, ``semantics``, ``particles``, ``plan_seed`` and ``plan_semantics``
    are as for :func:`arrange_up.figures.storyboard.draw_storyboard` (rollout ``i`` is rollout
    ``i`` of ``arrange-up evaluate`` with ``seed``). ``progress(done, total)`` is called after
    each rollout is computed. Raises :class:`WriterUnavailableError` before any work when the
    format cannot be written, ``ValueError`` for non-positive ``fps`` or
    ``frames_per_action``.
    """
    writer_name = check_writer(output)
    if fps <= 0 or frames_per_action < 1 or hold < 1:
        raise ValueError(
            f"fps must be positive and frames_per_action, hold at least 1; got {fps!r}, "
            f"{frames_per_action!r}, {hold!r}"
        )
    data = storyboard_data(
        problem,
        actions,
        rollouts=rollouts,
        seed=seed,
        semantics=semantics,
        particles=particles,
        plan_seed=plan_seed,
        progress=progress,
    )
    frames = frame_plan(len(actions), frames_per_action, hold)
    plt = pyplot()
    width, depth = problem.table.size
    scale = 6.0 / max(width, depth)
    fig = plt.figure(figsize=(width * scale + 0.8, depth * scale + 1.9))
    ax = fig.add_axes((0.1, 0.27, 0.86, 0.6))
    label = prediction_label(semantics, particles, plan_semantics)
    handles = legend_handles(problem, actions, rollouts=rollouts, shadows=has_shadows(data))

    def draw(index: int) -> None:
        k, t = frames[index]
        ax.clear()
        scene = scene_at(data, k, t)
        draw_scene(ax, problem, scene)
        if k == 0:
            title = "start"
        else:
            draw_action(ax, problem, actions[k - 1], t, travel=data["travel"][k - 1])
            title = f"action {k}/{len(actions)}: {describe(actions[k - 1], problem)}"
            if scene.nominal_failed:
                title += " (nominal failed)"
            if scene.no_prediction:
                title += " (no prediction)"
        ax.set_title(title, fontsize=10)
        style_axes(ax, problem, fontsize=9)

    fig.suptitle(f"{problem.name}: {label}", fontsize=10)
    fig.legend(handles=handles, loc="lower center", ncol=3, fontsize=8, frameon=False)
    output = Path(output)
    output.parent.mkdir(parents=True, exist_ok=True)
    try:
        movie = animation.FuncAnimation(fig, draw, frames=len(frames), repeat=False)
        writer = (
            animation.PillowWriter(fps=fps)
            if writer_name == "pillow"
            else animation.FFMpegWriter(fps=fps)
        )
        movie.save(output, writer=writer, dpi=dpi)
    finally:
        plt.close(fig)
    return output
