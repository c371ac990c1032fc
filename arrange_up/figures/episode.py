"""The storyboard of one closed-loop episode: one panel per executed action.

Each panel shows, after its action:

* the true world of the simulated executor, filled (the layer a plan's storyboard uses for
  the nominal poses);
* the posterior: every object's belief shadow (the interval fitted over the filter's
  particles) and the particles themselves in grey (the layer of a plan's rollouts);
* the action (:func:`~arrange_up.figures.scene.draw_action`) and what was sensed: the
  observed paddle pose, or the observed part poses, as red dashed outlines;
* in the title, the success estimate of the rest of the plan under the posterior, and
  whether the loop replanned there.

Drawn with the scene layers of :mod:`arrange_up.figures.scene`, like a plan's storyboard.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from matplotlib.lines import Line2D

from arrange_up.execution.replanning import LoopOutcome
from arrange_up.figures import render
from arrange_up.figures.backend import pyplot, save_figure
from arrange_up.figures.scene import (
    describe,
    draw_action,
    draw_scene,
    legend_handles,
    panel_figure,
    scene_at,
    style_axes,
)
from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import WorldState

__all__ = ["draw_episode"]

OBSERVED_COLOR = "#e7298a"  # magenta: no part colour


def episode_data(
    truth: list[WorldState] | tuple[WorldState, ...], outcome: LoopOutcome
) -> dict[str, Any]:
    """The scene data (:func:`~arrange_up.figures.scene.scene_at`) of a traced episode: the
    true states as the filled layer, the posteriors as shadows and their particles as the grey
    layer."""
    if outcome.prior is None:
        raise ValueError("the episode was not traced: run the loop with trace=True")
    beliefs = [outcome.prior, *(step.posterior for step in outcome.trace)]
    count = min(len(b) for b in beliefs)
    particles = [b.particles for b in beliefs]
    ghosts = [tuple(p[j] for p in particles) for j in range(count)]
    states = list(truth[: len(beliefs)])
    return {"nominal": states, "travel": [None] * len(outcome.trace), "beliefs": beliefs,
            "rollouts": ghosts}  # fmt: skip


def draw_episode(
    problem: ArrangementProblem,
    truth: list[WorldState] | tuple[WorldState, ...],
    outcome: LoopOutcome,
    output: str | Path,
    *,
    title: str = "",
    columns: int = 4,
    dpi: int = 110,
) -> Path:
    """Draw the storyboard of one traced episode (``outcome`` of ``ClosedLoop.run(...,
    trace=True)``, ``truth`` the executor's states) into a PNG, SVG or PDF, by the suffix of
    ``output``."""
    data = episode_data(truth, outcome)
    steps = outcome.trace
    replanned = {r.after for r in outcome.replans}
    plt = pyplot()
    fig, axes, _ = panel_figure(problem, len(steps) + 1, columns, row_margin=0.3, margin=1.4)
    try:
        for k, ax in enumerate(axes):
            draw_scene(ax, problem, scene_at(data, k))
            label = "start"
            if k > 0:
                step = steps[k - 1]
                draw_action(ax, problem, step.action)
                _draw_observation(ax, problem, step)
                label = f"{k}. {describe(step.action, problem)}"
                if step.estimate is not None:
                    label += f"; rest {100 * step.estimate:.0f}%"
                if k in replanned:
                    label += "; replan"
            ax.set_title(label, fontsize=8)
            style_axes(ax, problem, fontsize=7)
        fig.suptitle(
            title or f"{problem.name}: closed-loop episode, {len(steps)} actions", fontsize=10
        )
        handles = legend_handles(
            problem, [s.action for s in steps], rollouts=len(data["rollouts"]), shadows=True
        )
        # the layers mean other things here than in a plan's storyboard
        handles[1].set_label("true world")
        handles[2].set_label("posterior belief shadow")
        handles[3].set_label(f"{len(data['rollouts'])} posterior particles")
        handles.pop(4)
        handles.append(
            Line2D([], [], color=OBSERVED_COLOR, linestyle="--", label="observed (sensor)")
        )
        fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=7, frameon=False)
        fig.tight_layout(rect=(0, 0.7 / fig.get_figheight(), 1, 1))
        return save_figure(fig, output, dpi=dpi)
    finally:
        plt.close(fig)


def _draw_observation(ax: Any, problem: ArrangementProblem, step: Any) -> None:
    observation = step.observation
    if observation.paddle is not None:
        spec = problem.object(step.action.manipulator)
        render.draw_object(
            ax, spec, observation.paddle, color=OBSERVED_COLOR, fill=False, linestyle="--",
            zorder=7,
        )  # fmt: skip
    for name, pose in observation.poses or ():
        render.draw_object(
            ax, problem.object(name), pose, color=OBSERVED_COLOR, fill=False, linestyle="--",
            linewidth=0.8, zorder=7,
        )  # fmt: skip
