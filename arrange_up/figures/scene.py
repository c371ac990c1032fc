"""One picture of a plan's execution at a moment: what storyboard panels and animation frames
share.

A :class:`Scene` holds what is on the table at that moment: the nominal (noise-free) poses,
the predicted belief shadows and the poses of the noisy rollouts, each with an opacity.
:func:`scene_at` computes it from the data of
:func:`arrange_up.figures.storyboard.storyboard_data`, after action ``k`` or a fraction ``t``
of the way through it; :func:`draw_scene` draws it with the goal, :func:`draw_action` the
action, :func:`style_axes` the axes in the problem's units and :func:`legend_handles` the
legend.

The layers are drawn so that they cannot be confused: the goal as solid green outlines, the
predicted belief shadows as translucent hulls with dashed boxes in the part's colour, the
nominal poses filled, the rollouts in translucent grey (thin black outlines from the action
where a rollout failed), a place's commanded pose dotted black.

Between two recorded states ``t`` interpolates poses linearly (angles the short way round),
an object placed fades in and an object picked fades out: the physics records the state after
each action, not the motion during it, so the motion drawn during a push is this
interpolation, not the simulated trajectory.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from matplotlib.axes import Axes
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.ticker import MaxNLocator

from arrange_up.figures import render
from arrange_up.figures.backend import pyplot
from arrange_up.geometry.se2 import compose, rotate
from arrange_up.model.problem import ArrangementProblem, ObjectKind, Pose
from arrange_up.model.world import Action, Pick, Place, Push

__all__ = [
    "FAILED_COLOR",
    "GOAL_COLOR",
    "ROLLOUT_ALPHA",
    "ROLLOUT_COLOR",
    "Scene",
    "describe",
    "draw_action",
    "draw_goal_outlines",
    "draw_scene",
    "has_shadows",
    "legend_handles",
    "prediction_label",
    "scene_at",
    "style_axes",
]

ROLLOUT_COLOR = "0.35"
ROLLOUT_ALPHA = 0.07
#: Failed rollouts are thin black outlines (the part colours include red and grey).
FAILED_COLOR = "black"
FAILED_ALPHA = 0.3
GOAL_COLOR = "#1a9850"

#: (name, pose, opacity) of one object.
Placed = tuple[str, Pose, float]


@dataclass(frozen=True)
class Scene:
    """What is on the table at one moment of a plan's execution.

    ``nominal``: (name, pose, opacity) of each object of the noise-free execution;
    ``shadows``: (name, centre, half-widths, opacity) of each predicted belief interval;
    ``rollouts``: for each noisy rollout, its objects and whether it has failed by then.
    ``nominal_failed`` says the noise-free execution failed by this action (its last state is
    shown), ``no_prediction`` that the semantics made no prediction here (no shadows shown).
    """

    nominal: tuple[Placed, ...]
    shadows: tuple[tuple[str, Pose, Pose, float], ...]
    rollouts: tuple[tuple[tuple[Placed, ...], bool], ...]
    nominal_failed: bool = False
    no_prediction: bool = False


def _lerp_pose(a: Pose, b: Pose, t: float) -> Pose:
    turn = math.remainder(b[2] - a[2], 2 * math.pi)
    return (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * turn)


def _blend(
    before: dict[str, Any] | None, after: dict[str, Any] | None, t: float, lerp: Any
) -> list[tuple[str, Any, float]]:
    """(name, value, opacity) between two name -> value maps ``t`` of the way: values in both
    interpolated by ``lerp``, the others faded in (only after) or out (only before)."""
    before, after = before or {}, after or {}
    out = [
        (
            name,
            lerp(value, after[name], t) if name in after else value,
            1.0 if name in after else 1 - t,
        )
        for name, value in before.items()
    ]
    out += [(name, value, t) for name, value in after.items() if name not in before]
    return [item for item in out if item[2] > 0]


def _intervals(belief: Any) -> dict[str, tuple[Pose, Pose]] | None:
    if belief is None:
        return None
    return {name: (i.center, i.half) for name, i in belief.intervals.objects}


def _lerp_interval(a: tuple[Pose, Pose], b: tuple[Pose, Pose], t: float) -> tuple[Pose, Pose]:
    half = tuple(x + t * (y - x) for x, y in zip(a[1], b[1], strict=True))
    return _lerp_pose(a[0], b[0], t), half  # type: ignore[return-value]


def scene_at(data: dict[str, Any], k: int, t: float = 1.0) -> Scene:
    """The scene ``t`` (0..1) of the way through action ``k`` (1-based; ``k`` 0 is the start)
    of the storyboard data ``data``; ``t`` 1 is the state after the action."""
    if k == 0:
        t = 1.0
    nominal, beliefs = data["nominal"], data["beliefs"]
    last = max((j for j in range(k + 1) if nominal[j] is not None), default=None)
    failed = nominal[k] is None
    if last is None:
        poses: list[Placed] = []
    elif failed or k == 0:
        poses = [(n, p, 1.0) for n, p in nominal[last].poses]
    else:
        poses = _blend(dict(nominal[k - 1].poses), dict(nominal[k].poses), t, _lerp_pose)
    no_prediction = beliefs[k] is None
    if no_prediction or k == 0:
        shadows_at = _intervals(beliefs[k])
        shadows = [(n, c, h, 1.0) for n, (c, h) in (shadows_at or {}).items()]
    else:
        blended = _blend(_intervals(beliefs[k - 1]), _intervals(beliefs[k]), t, _lerp_interval)
        shadows = [(n, c, h, alpha) for n, (c, h), alpha in blended]
    rollouts = []
    for trace in data["rollouts"]:
        if len(trace) > k:
            if k == 0:
                placed = [(n, p, 1.0) for n, p in trace[0].poses]
            else:
                placed = _blend(dict(trace[k - 1].poses), dict(trace[k].poses), t, _lerp_pose)
            rollouts.append((tuple(placed), False))
        elif trace:
            rollouts.append((tuple((n, p, 1.0) for n, p in trace[-1].poses), True))
    return Scene(
        nominal=tuple(poses),
        shadows=tuple(shadows),
        rollouts=tuple(rollouts),
        nominal_failed=k > 0 and failed,
        no_prediction=k > 0 and no_prediction,
    )


def has_shadows(data: dict[str, Any]) -> bool:
    """Whether any predicted belief of the storyboard data ``data`` has a shadow (a non-zero
    half-width): a deterministic prediction has none."""
    return any(
        any(h != 0 for h in interval.half)
        for belief in data["beliefs"]
        if belief is not None
        for _, interval in belief.intervals.objects
    )


def draw_goal_outlines(
    ax: Axes, problem: ArrangementProblem, *, reference_pose: Pose | None = None
) -> list[Any]:
    """The goal as solid green outlines of each goal part at its target pose, with the
    tolerance box of its centre; a relative goal around ``reference_pose`` (nothing without
    it). Returns the artists added."""
    goal = problem.goal
    if goal.is_relative and reference_pose is None:
        return []
    artists: list[Any] = []
    half = render.goal_tolerance_half_widths(problem)
    for name, target in goal.targets:
        pose = (
            compose(reference_pose, target)
            if goal.is_relative and reference_pose is not None
            else target
        )
        spec = problem.object(name)
        artists += render.draw_object(
            ax, spec, pose, color=GOAL_COLOR, fill=False, linewidth=2.0, zorder=3.5
        )
        if half[0] > 0 or half[1] > 0:
            artists += ax.plot(
                [pose[0] - half[0], pose[0] + half[0], pose[0] + half[0], pose[0] - half[0],
                 pose[0] - half[0]],
                [pose[1] - half[1], pose[1] - half[1], pose[1] + half[1], pose[1] + half[1],
                 pose[1] - half[1]],
                color=GOAL_COLOR, linewidth=0.8, zorder=3.5,
            )  # fmt: skip
    return render.clip_to_table(ax, problem, artists)


def draw_scene(ax: Axes, problem: ArrangementProblem, scene: Scene) -> None:
    """Draw the table, the goal, the rollouts, the predicted shadows and the nominal poses of
    ``scene`` onto ``ax`` (the layers of the module docstring)."""
    render.draw_table(ax, problem)
    reference = None
    if problem.goal.is_relative:
        reference = next((p for n, p, _ in scene.nominal if n == problem.goal.reference), None)
    draw_goal_outlines(ax, problem, reference_pose=reference)
    for placed, failed in scene.rollouts:
        for name, pose, alpha in placed:
            if failed:
                render.draw_object(
                    ax,
                    problem.object(name),
                    pose,
                    color=FAILED_COLOR,
                    fill=False,
                    alpha=FAILED_ALPHA,
                    linewidth=0.6,
                    zorder=2.6,
                )
            else:
                render.draw_object(
                    ax,
                    problem.object(name),
                    pose,
                    color=ROLLOUT_COLOR,
                    alpha=ROLLOUT_ALPHA * alpha,
                    linewidth=0.0,
                    zorder=2.5,
                )
    for name, center, half, alpha in scene.shadows:
        render.draw_shadows(
            ax,
            problem.object(name),
            center,
            half,
            color=render.object_color(problem, name),
            alpha=render.SHADOW_ALPHA * alpha,
            zorder=2,
        )
    for name, pose, alpha in scene.nominal:
        color = render.object_color(problem, name)
        render.draw_object(
            ax,
            problem.object(name),
            pose,
            color=color,
            alpha=alpha,
            label=name if alpha > 0.5 else None,
            zorder=4,
        )


def draw_action(
    ax: Axes,
    problem: ArrangementProblem,
    action: Action,
    t: float = 1.0,
    *,
    travel: float | None = None,
) -> None:
    """Draw ``action``: a place's commanded pose dotted black; a push's manipulator ``t`` of
    the way along its ``travel`` (how far it went in the noise-free push; the commanded
    distance when None), with an arrow from its approach pose as long as the commanded
    distance (under the compliant controller a resisted push stops short of the arrow's
    head); a pick as a note."""
    if isinstance(action, Place):
        spec = problem.object(action.obj)
        render.draw_object(
            ax, spec, action.pose, color="black", fill=False, linestyle=":", zorder=5
        )
    elif isinstance(action, Push):
        spec = problem.object(action.manipulator)
        ux, uy = rotate(spec.push_direction, action.pose[2])
        dx, dy = ux * action.distance, uy * action.distance
        went = t * (action.distance if travel is None else travel)
        x, y, theta = action.pose
        render.draw_object(ax, spec, (x + went * ux, y + went * uy, theta), color="0.15", zorder=5)
        ax.annotate(
            "",
            xy=(x + dx, y + dy),
            xytext=(x, y),
            arrowprops={"arrowstyle": "->", "color": "black", "lw": 1.2},
            zorder=6,
        )
    elif isinstance(action, Pick):
        spec = problem.object(action.obj)
        if spec.kind is not ObjectKind.OBSTACLE:
            ax.text(0.02, 0.95, f"pick {action.obj}", transform=ax.transAxes, fontsize=7, va="top")


def describe(action: Action, problem: ArrangementProblem) -> str:
    """A short description of ``action`` in the problem's units: lengths with 2 decimals,
    angles in whole degrees or in radians with 2 decimals, each angle with its unit."""
    units = problem.units
    if isinstance(action, Place):
        x, y, t = units.pose_out(action.pose)
        # rounded first: -0.02 deg reads "0", not "-0"
        angle = f"{round(t)} deg" if units.angle == "deg" else f"{round(t, 2) + 0.0:.2f} rad"
        return f"place {action.obj} at ({x:.2f}, {y:.2f}, {angle})"
    if isinstance(action, Push):
        return f"push {units.length_out(action.distance):.2f} {units.length}"
    return f"pick {action.obj}"


def panel_figure(
    problem: ArrangementProblem, panels: int, columns: int, *, row_margin: float, margin: float
) -> tuple[Any, list[Axes], int]:
    """A storyboard's figure: ``panels`` table panels in rows of at most ``columns``, the
    table's longer side 3.6 in long, each row ``row_margin`` inches taller than its table (its
    titles and axis labels) and the figure ``margin`` inches taller still (title and legend);
    the spare axes of the last row are switched off. Returns the figure, the panels' axes in
    reading order and the number of columns used."""
    columns = max(1, min(columns, panels))
    rows = math.ceil(panels / columns)
    width, depth = problem.table.size
    scale = 3.6 / max(width, depth)
    fig, grid = pyplot().subplots(
        rows,
        columns,
        figsize=(columns * width * scale + 0.4, rows * (depth * scale + row_margin) + margin),
        squeeze=False,
    )
    axes = [ax for row in grid for ax in row]
    for ax in axes[panels:]:
        ax.axis("off")
    return fig, axes[:panels], columns


def style_axes(ax: Axes, problem: ArrangementProblem, *, fontsize: float = 7) -> None:
    """Equal-aspect axes around the table, ticked and labelled in the problem's length unit
    (the figures draw in inches; the ticks are placed at round values of the user's unit)."""
    width, depth = problem.table.size
    ax.set_aspect("equal")
    ax.set_xlim(-0.6, width + 0.6)
    ax.set_ylim(-0.6, depth + 0.6)
    units = problem.units
    for axis, (lo, hi), label in (
        (ax.xaxis, ax.get_xlim(), "x"),
        (ax.yaxis, ax.get_ylim(), "y"),
    ):
        ticks = [
            v
            for v in MaxNLocator(5).tick_values(units.length_out(lo), units.length_out(hi))
            if units.length_out(lo) <= v <= units.length_out(hi)
        ]
        axis.set_ticks([units.length_in(v) for v in ticks], [f"{v:g}" for v in ticks])
        axis.set_label_text(f"{label} ({units.length})", fontsize=fontsize)
    ax.tick_params(labelsize=fontsize - 1)


def legend_handles(
    problem: ArrangementProblem, actions: Iterable[Action], *, rollouts: int, shadows: bool
) -> list[Any]:
    """Proxy artists for the layers a plan's picture has: the goal, nominal poses, predicted
    shadows (with ``shadows``), rollouts (``rollouts`` > 0) and the kinds of ``actions``."""
    sample = render.PART_COLORS[0]
    handles: list[Any] = [
        Line2D([], [], color=GOAL_COLOR, linewidth=1.6, label="goal (± tolerance of centre)"),
        Patch(facecolor=sample, edgecolor="black", label="nominal pose (no noise)"),
    ]
    if shadows:
        handles.append(
            Patch(
                facecolor=sample,
                alpha=render.SHADOW_ALPHA + 0.1,
                edgecolor=sample,
                linestyle="--",
                label="predicted belief shadow",
            )
        )
    if rollouts:
        handles.append(
            Patch(facecolor=ROLLOUT_COLOR, alpha=0.4, label=f"{rollouts} noisy rollouts")
        )
        handles.append(
            Patch(facecolor="none", edgecolor=FAILED_COLOR, linewidth=0.6, label="rollout failed")
        )
    kinds = {type(a) for a in actions}
    if Place in kinds:
        handles.append(Line2D([], [], color="black", linestyle=":", label="commanded place"))
    if Push in kinds:
        handles.append(
            Line2D([], [], color="0.15", marker=r"$\rightarrow$", markersize=10, linestyle="none",
                   label="manipulator, push")
        )  # fmt: skip
    return handles


def prediction_label(semantics: str, particles: int, plan_semantics: str | None) -> str:
    """What the shadows show, for a figure's title: the semantics replayed and, when the plan
    was made otherwise (e.g. a repaired plan), that this is a replay of the plan."""
    if plan_semantics is None or plan_semantics == semantics:
        what = f"{semantics}, {particles} particles" if semantics == "particles" else semantics
        return f"predicted shadows ({what})"
    what = f"the {semantics} semantics"
    if semantics == "particles":
        what = f"the particle semantics with {particles} particles"
    return f"{plan_semantics} plan; shadows predicted by replaying it in {what}"
