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

The first panel shows the start; the goal is drawn faintly in every panel.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from arrange_up.evaluation.evaluate import trace_rollout
from arrange_up.figures import render
from arrange_up.figures.backend import figure_format, pyplot
from arrange_up.model.problem import ArrangementProblem, ObjectKind
from arrange_up.model.world import (
    Action,
    Pick,
    Place,
    Push,
    WorldState,
    nominal_initial_state,
    nominal_noise,
)
from arrange_up.physics.simulation import simulate
from arrange_up.transitions import make_semantics

ROLLOUT_COLOR = "0.35"
ROLLOUT_ALPHA = 0.07


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
    failure), ``beliefs`` (the semantics' predicted belief before and after each action;
    ``None`` where it made no prediction) and ``rollouts`` (for each rollout, its states, cut
    short where it failed).
    """
    nominal: list[WorldState | None] = [nominal_initial_state(problem)]
    for action in actions:
        state = nominal[-1]
        if state is None:
            nominal.append(None)
            continue
        try:
            outcome = simulate(problem, state, action, nominal_noise(problem))
            nominal.append(outcome.state if outcome.ok else None)
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
    return {"nominal": nominal, "beliefs": beliefs, "rollouts": traces}


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
    columns: int = 4,
    dpi: int = 110,
    progress: Callable[[int, int], None] | None = None,
) -> Path:
    """Draw the storyboard of a plan into a PNG, SVG or PDF, by the suffix of ``output`` (see
    the module docstring)."""
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
    panels = len(actions) + 1
    columns = max(1, min(columns, panels))
    rows = math.ceil(panels / columns)
    width, depth = problem.table.size
    scale = 3.6 / max(width, depth)
    fig, axes = plt.subplots(
        rows,
        columns,
        figsize=(columns * width * scale + 0.4, rows * depth * scale + 0.9),
        squeeze=False,
    )
    try:
        for k in range(rows * columns):
            ax = axes[k // columns][k % columns]
            if k >= panels:
                ax.axis("off")
                continue
            _draw_panel(ax, problem, data, actions, k)
        fig.suptitle(
            f"{problem.name}: {len(actions)} actions, {rollouts} noisy rollouts in grey, "
            f"predicted shadows ({semantics})",
            fontsize=10,
        )
        fig.tight_layout()
        output = Path(output)
        output.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(output, dpi=dpi, format=figure_format(output))
    finally:
        plt.close(fig)
    return output


def _draw_panel(ax, problem: ArrangementProblem, data, actions, k: int) -> None:
    render.draw_table(ax, problem)
    if not problem.goal.is_relative:
        for artist in render.draw_goal(ax, problem, tolerance=False):
            artist.set_alpha(0.35)
    # Rollouts in grey.
    for trace in data["rollouts"]:
        if k < len(trace):
            for name, pose in trace[k].poses:
                render.draw_object(
                    ax,
                    problem.object(name),
                    pose,
                    color=ROLLOUT_COLOR,
                    alpha=ROLLOUT_ALPHA,
                    linewidth=0.0,
                    zorder=2.5,
                )
    # Predicted belief shadows.
    belief = data["beliefs"][k]
    if belief is not None:
        for name, interval in belief.intervals.objects:
            color = render.object_color(problem, name)
            render.draw_shadows(
                ax, problem.object(name), interval.center, interval.half, color=color, zorder=2
            )
    # Nominal poses.
    state = data["nominal"][k]
    if state is not None:
        for name, pose in state.poses:
            color = render.object_color(problem, name)
            render.draw_object(ax, problem.object(name), pose, color=color, label=name, zorder=4)
    title = "start" if k == 0 else f"{k}. {_describe(actions[k - 1], problem)}"
    if k > 0:
        _draw_action(ax, problem, actions[k - 1])
        if state is None:
            title += " (nominal failed)"
        if belief is None:
            title += " (no prediction)"
    ax.set_title(title, fontsize=8)
    ax.set_aspect("equal")
    width, depth = problem.table.size
    ax.set_xlim(-0.6, width + 0.6)
    ax.set_ylim(-0.6, depth + 0.6)
    ax.tick_params(labelsize=6)


def _draw_action(ax, problem: ArrangementProblem, action: Action) -> None:
    if isinstance(action, Place):
        spec = problem.object(action.obj)
        render.draw_object(
            ax, spec, action.pose, color="black", fill=False, linestyle=":", zorder=5
        )
    elif isinstance(action, Push):
        spec = problem.object(action.manipulator)
        render.draw_object(ax, spec, action.pose, color="0.15", zorder=5)
        px, py = spec.push_direction
        c, s = math.cos(action.pose[2]), math.sin(action.pose[2])
        dx, dy = (c * px - s * py) * action.distance, (s * px + c * py) * action.distance
        ax.annotate(
            "",
            xy=(action.pose[0] + dx, action.pose[1] + dy),
            xytext=(action.pose[0], action.pose[1]),
            arrowprops={"arrowstyle": "->", "color": "black", "lw": 1.2},
            zorder=6,
        )
    elif isinstance(action, Pick):
        spec = problem.object(action.obj)
        if spec.kind is not ObjectKind.OBSTACLE:
            ax.text(0.02, 0.95, f"pick {action.obj}", transform=ax.transAxes, fontsize=7, va="top")


def _describe(action: Action, problem: ArrangementProblem) -> str:
    units = problem.units
    if isinstance(action, Place):
        x, y, t = units.pose_out(action.pose)
        return f"place {action.obj} at ({x:.2f}, {y:.2f}, {t:.0f})"
    if isinstance(action, Push):
        return f"push {units.length_out(action.distance):.2f} {units.length}"
    return f"pick {action.obj}"
