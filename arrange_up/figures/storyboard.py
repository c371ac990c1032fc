"""Storyboards: one panel per plan action, like thesis Figure 3-11.

Each panel shows the state after its action:

* the action itself — a place as the commanded outline with its place-uncertainty shadow, a
  push as the manipulator at its approach pose with an arrow as long as the commanded
  distance, a pick as a crossed-out outline;
* the predicted belief after the action: every object's belief shadow (hull and box) from
  the interval fitted over the planner's semantics (replayed with the plan's own semantics,
  particle count and seed, so these are exactly the beliefs the planner saw);
* the nominal poses (noise-free physics), filled;
* the poses reached by ``rollouts`` noisy rollouts, overlaid in grey — rollout ``i`` is the
  same as rollout ``i`` of ``arrange-up evaluate`` with the same seed.

The first panel shows the start; the goal is drawn in every panel as solid green outlines
(:mod:`arrange_up.figures.scene` draws the layers, the same way as the animation's frames), a
legend below the panels says which layer is which, the axes are in the problem's length unit.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from arrange_up.evaluation.rollouts import trace_rollout
from arrange_up.figures.backend import pyplot, save_figure
from arrange_up.figures.scene import (
    describe,
    draw_action,
    draw_scene,
    has_shadows,
    legend_handles,
    panel_figure,
    prediction_label,
    scene_at,
    style_axes,
)
from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import (
    Action,
    Push,
    WorldState,
    nominal_initial_state,
    nominal_noise,
)
from arrange_up.physics.simulation import simulate
from arrange_up.transitions import make_semantics


def storyboard_data(
    problem: ArrangementProblem,
    actions: Sequence[Action],
    *,
    rollouts: int = 50,
    seed: int = 0,
    semantics: str = "deterministic",
    particles: int = 1,
    plan_seed: int = 0,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Any]:
    """Compute what a storyboard draws: nominal states, predicted beliefs, rollout states.

    Returns a dict with ``nominal`` (states before and after each action; ``None`` after a
    failure), ``travel`` (for each action, how far the manipulator travelled in the noise-free
    push, which stops short of the commanded distance when the compliant controller stalls;
    ``None`` for a place, a pick or a failed action), ``beliefs`` (the semantics' predicted
    belief before and after each action; ``None`` where it made no prediction) and
    ``rollouts`` (for each rollout, its states, cut short where it failed).
    """
    nominal: list[WorldState | None] = [nominal_initial_state(problem)]
    travel: list[float | None] = []
    for action in actions:
        state = nominal[-1]
        travel.append(None)
        if state is None:
            nominal.append(None)
            continue
        try:
            outcome = simulate(problem, state, action, nominal_noise(problem))
            nominal.append(outcome.state if outcome.ok else None)
            if outcome.ok and isinstance(action, Push):
                travel[-1] = outcome.manipulator_travel
        except ValueError:
            nominal.append(None)

    model = make_semantics(semantics, problem, particles=particles, seed=plan_seed)
    try:
        beliefs: list[Any] = [model.initial_belief()]
        for action in actions:
            beliefs.append(None if beliefs[-1] is None else model.apply(beliefs[-1], action))
    finally:
        model.close()

    traces = []
    for i in range(rollouts):
        traces.append(trace_rollout(problem, actions, seed, i))
        if progress is not None:
            progress(i + 1, rollouts)
    return {"nominal": nominal, "travel": travel, "beliefs": beliefs, "rollouts": traces}


def draw_storyboard(
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
    columns: int = 4,
    dpi: int = 110,
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Draw the storyboard of a plan into a PNG, SVG or PDF, by the suffix of ``output`` (see
    the module docstring).

    ``semantics``, ``particles`` and ``plan_seed`` are those the shadows are predicted with;
    ``plan_semantics`` is what the plan file records when it differs (e.g. ``fixtures`` for a
    repaired plan), and the title then says the shadows are a replay.
    """
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
    plt = pyplot()
    fig, axes, columns = panel_figure(
        problem, len(actions) + 1, columns, row_margin=LABEL_HEIGHT, margin=LEGEND_HEIGHT + 0.9
    )
    try:
        for k, ax in enumerate(axes):
            _draw_panel(ax, problem, data, actions, k)
        label = prediction_label(semantics, particles, plan_semantics)
        fig.suptitle(f"{problem.name}: {len(actions)} actions; {label}", fontsize=10)
        handles = legend_handles(problem, actions, rollouts=rollouts, shadows=has_shadows(data))
        fig.legend(
            handles=handles,
            loc="lower center",
            ncol=min(len(handles), max(2, columns * 2)),
            fontsize=7,
            frameon=False,
        )
        # the panels between the legend's strip and the title's: tight_layout alone lets the
        # first row's titles run up into the figure's title
        height = fig.get_figheight()
        fig.tight_layout(rect=(0, LEGEND_HEIGHT / height, 1, 1 - TITLE_HEIGHT / height))
        return save_figure(fig, output, dpi=dpi)
    finally:
        plt.close(fig)


#: Inches below the panels for the legend, above them for the title, and below each row for
#: its axis labels.
LEGEND_HEIGHT = 0.5
TITLE_HEIGHT = 0.4
LABEL_HEIGHT = 0.4


def _draw_panel(ax, problem: ArrangementProblem, data, actions, k: int) -> None:
    scene = scene_at(data, k)
    draw_scene(ax, problem, scene)
    title = "start" if k == 0 else f"{k}. {describe(actions[k - 1], problem)}"
    if k > 0:
        draw_action(ax, problem, actions[k - 1], travel=data["travel"][k - 1])
        if scene.nominal_failed:
            title += " (nominal failed)"
        if scene.no_prediction:
            title += " (no prediction)"
    ax.set_title(title, fontsize=8)
    style_axes(ax, problem, fontsize=7)
