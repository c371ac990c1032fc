"""Pictures of problems: the table, the initial belief and the goal, like thesis Figures 2-8/2-9.

:func:`draw_problem` writes one picture (PNG, SVG or PDF) of a whole problem. It is built from
one helper per layer, each drawing onto a given matplotlib ``Axes`` so that other pictures (a
storyboard with one panel per plan action, a report) can reuse them:

* :func:`draw_table`: the table surface, its walls (thick dark bars on their edges) and the
  fixed obstacles (solid grey).
* :func:`draw_object`: one object's footprint at a pose, filled or as an outline, labelled.
* :func:`draw_shadows`: the belief shadows of an object whose pose lies in ``pose +-
  half_widths``: the convex hull of every footprint (a translucent patch) and its axis-aligned
  bounding box (dashed).
* :func:`draw_initial`: every object on the table at its nominal initial pose with its shadows.
* :func:`draw_goal`: an absolute goal's target outlines and tolerance regions, or a relative
  goal's arrangement around the reference part.

Everything is drawn in inches (the problem's internal unit), whatever units the file used; the
axes are ticked and labelled, and the notes written, in the file's own units. Figures are drawn
with the non-interactive Agg backend (:func:`arrange_up.figures.backend.pyplot`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle
from matplotlib.patches import Polygon as PolygonPatch
from matplotlib.ticker import FuncFormatter, MaxNLocator
from shapely.geometry import Polygon

from arrange_up.figures.backend import pyplot, save_figure
from arrange_up.geometry import shapes as geometry
from arrange_up.geometry.se2 import compose, rotate
from arrange_up.io.domains import first_sentence
from arrange_up.model.problem import ArrangementProblem, HalfWidths, ObjectKind, ObjectSpec, Pose
from arrange_up.model.units import Units

__all__ = [
    "PART_COLORS",
    "clip_to_table",
    "compose",
    "draw_goal",
    "draw_heatmap",
    "draw_initial",
    "draw_legend",
    "draw_object",
    "draw_problem",
    "draw_relative_goal",
    "draw_shadows",
    "draw_table",
    "goal_tolerance_half_widths",
    "heatmap_figure",
    "object_color",
    "off_table_note",
    "unit_axes",
    "write_heatmap",
]

#: Fill colours of parts, in the order the problem declares them (matplotlib's tab10, minus the
#: grey that obstacles use).
PART_COLORS: tuple[str, ...] = (
    "#1f77b4",
    "#d62728",
    "#2ca02c",
    "#9467bd",
    "#ff7f0e",
    "#17becf",
    "#8c564b",
    "#e377c2",
    "#bcbd22",
)
TABLE_COLOR = "#f4ecd8"
TABLE_EDGE = "#8a7a5a"
WALL_COLOR = "#2b2b2b"
OBSTACLE_COLOR = "#8c8c8c"
FIXTURE_COLOR = "#b8860b"
MANIPULATOR_COLOR = "#3a3a3a"
#: Drawn thickness of walls (inches): thick enough to read, thin next to a 1-inch block.
WALL_DRAW_THICKNESS = 0.3
#: The drawing scale label sizes assume: points on the page per inch on the table (the
#: pictures of :func:`draw_problem` use about 30 to 40).
POINTS_PER_INCH = 30.0
SHADOW_ALPHA = 0.16
TOLERANCE_ALPHA = 0.14


# ---------------------------------------------------------------------------------------------
# small helpers
# ---------------------------------------------------------------------------------------------
def object_color(problem: ArrangementProblem, name: str) -> str:
    """The colour ``name`` is drawn in: parts get :data:`PART_COLORS` in declaration order;
    fixtures, manipulators and obstacles a colour per kind."""
    spec = problem.object(name)
    if spec.kind is ObjectKind.PART:
        index = [p.name for p in problem.parts].index(name)
        return PART_COLORS[index % len(PART_COLORS)]
    return {
        ObjectKind.FIXTURE: FIXTURE_COLOR,
        ObjectKind.MANIPULATOR: MANIPULATOR_COLOR,
        ObjectKind.OBSTACLE: OBSTACLE_COLOR,
    }[spec.kind]


def goal_tolerance_half_widths(problem: ArrangementProblem) -> HalfWidths:
    """The goal tolerance as pose half-widths; an any-angle tolerance becomes a full turn."""
    dx, dy, dtheta = problem.goal.tolerance
    return (dx, dy, math.pi if dtheta is None else dtheta)


def _rings(geom: Any) -> list[Any]:
    """The exterior rings (coordinate lists) of a shapely geometry's polygons (a footprint is
    already the union of its convex parts, so a non-convex part has one outline)."""
    if isinstance(geom, Polygon):
        polygons = [geom]
    else:
        polygons = [g for g in getattr(geom, "geoms", []) if isinstance(g, Polygon)]
    return [list(p.exterior.coords) for p in polygons if not p.is_empty]


def _polygon_patches(geom: Any, **style: Any) -> list[Any]:
    return [PolygonPatch(ring, closed=True, **style) for ring in _rings(geom)]


def _label_size(geom: Any, label: str) -> float:
    """A font size (points) at which ``label`` fits inside ``geom``'s width on the page."""
    xmin, _, xmax, _ = geom.bounds
    fits = 0.85 * (xmax - xmin) * POINTS_PER_INCH / (0.62 * max(len(label), 1))
    return max(5.0, min(11.0, fits))


def _is_zero(half_widths: Sequence[float]) -> bool:
    return all(abs(v) < 1e-12 for v in half_widths)


def _describe_shape(spec: ObjectSpec, units: Units) -> str:
    """The size of ``spec``'s shape in ``units``' length unit."""
    out = units.length_out
    if spec.shape.box is not None:
        w, h = spec.shape.box
        return f"{out(w):.3g} x {out(h):.3g} {units.length}"
    xmin, ymin, xmax, ymax = spec.shape.extent
    size = f"{out(xmax - xmin):.3g} x {out(ymax - ymin):.3g} {units.length}"
    return f"{spec.shape.name or 'polygon'}, {size}"


# ---------------------------------------------------------------------------------------------
# layers
# ---------------------------------------------------------------------------------------------
def draw_table(ax: Axes, problem: ArrangementProblem, *, obstacles: bool = True) -> list[Any]:
    """Draw the table surface, its walls and (unless ``obstacles=False``) the fixed obstacles.

    Walls are dark bars just outside the table edges they guard, as thick as
    :data:`WALL_DRAW_THICKNESS`; an edge without a wall is drawn as a thin dashed line (a part
    pushed across it falls off). Returns the artists added.
    """
    width, depth = problem.table.size
    artists: list[Any] = [
        ax.add_patch(
            Rectangle((0.0, 0.0), width, depth, facecolor=TABLE_COLOR, edgecolor="none", zorder=0)
        )
    ]
    edges = {
        "left": ((0.0, 0.0), (0.0, depth)),
        "right": ((width, width), (0.0, depth)),
        "bottom": ((0.0, width), (0.0, 0.0)),
        "top": ((0.0, width), (depth, depth)),
    }
    walls = set(problem.table.walls)
    for edge, (xs, ys) in edges.items():
        if edge not in walls:
            artists += ax.plot(xs, ys, color=TABLE_EDGE, linestyle="--", linewidth=1.0, zorder=1)
    for box in geometry.wall_boxes(
        problem.table.size, problem.table.walls, thickness=WALL_DRAW_THICKNESS
    ).values():
        xmin, ymin, xmax, ymax = _box_bounds(box)
        artists.append(
            ax.add_patch(
                Rectangle(
                    (xmin, ymin),
                    xmax - xmin,
                    ymax - ymin,
                    facecolor=WALL_COLOR,
                    edgecolor=WALL_COLOR,
                    zorder=2.8,
                )
            )
        )
    if obstacles:
        for spec in problem.obstacles:
            assert spec.pose is not None
            artists += draw_object(ax, spec, spec.pose, color=OBSTACLE_COLOR, zorder=2)
    return artists


def _box_bounds(box: Any) -> tuple[float, float, float, float]:
    """``(xmin, ymin, xmax, ymax)`` as floats (geometry's ``Box``)."""
    xmin, ymin, xmax, ymax = (float(v) for v in box)
    return xmin, ymin, xmax, ymax


def draw_object(
    ax: Axes,
    spec: ObjectSpec,
    pose: Pose,
    *,
    color: str = PART_COLORS[0],
    fill: bool = True,
    alpha: float = 1.0,
    linestyle: str = "-",
    linewidth: float = 1.2,
    label: str | None = None,
    label_size: float | None = None,
    zorder: float = 3,
) -> list[Any]:
    """Draw ``spec``'s footprint at ``pose`` (world frame, inches and radians).

    ``fill=True`` paints the shape in ``color`` with a darker outline; ``fill=False`` draws only
    its outline in ``color`` (``linestyle="--"`` for a goal target). ``label`` is written at the
    pose's origin (the shape's centroid), white on a filled shape and coloured on an outline, in
    ``label_size`` points (by default a size that fits the footprint's width at
    :data:`POINTS_PER_INCH`). Returns the artists added.
    """
    geom = geometry.footprint(spec.shape.parts, pose)
    if fill:
        style = {
            "facecolor": color,
            "edgecolor": "black",
            "alpha": alpha,
            "linewidth": linewidth,
            "linestyle": linestyle,
        }
    else:
        style = {
            "facecolor": "none",
            "edgecolor": color,
            "alpha": alpha,
            "linewidth": linewidth * 1.3,
            "linestyle": linestyle,
        }
    artists: list[Any] = [ax.add_patch(p) for p in _polygon_patches(geom, zorder=zorder, **style)]
    if label:
        size = label_size if label_size is not None else _label_size(geom, label)
        artists.append(
            ax.text(
                pose[0],
                pose[1],
                label,
                ha="center",
                va="center",
                fontsize=size,
                fontweight="bold" if fill else "normal",
                fontstyle="normal" if fill else "italic",
                color="white" if fill else color,
                zorder=zorder + 0.5,
            )
        )
    return artists


def draw_shadows(
    ax: Axes,
    spec: ObjectSpec,
    pose: Pose,
    half_widths: HalfWidths,
    *,
    color: str = PART_COLORS[0],
    hull: bool = True,
    box: bool = True,
    alpha: float = SHADOW_ALPHA,
    zorder: float = 2,
) -> list[Any]:
    """Draw the belief shadows of ``spec`` with its pose anywhere in ``pose +- half_widths``.

    The convex hull of all those footprints is a translucent patch (``hull``), its
    axis-aligned bounding box a dashed rectangle (``box``); both in ``color``. Nothing is drawn
    for zero half-widths (the shadow is the footprint itself). Returns the artists added.
    """
    if _is_zero(half_widths):
        return []
    artists: list[Any] = []
    if hull:
        shadow = geometry.shadow_hull(spec.shape.parts, pose, half_widths)
        artists += [
            ax.add_patch(p)
            for p in _polygon_patches(
                shadow, facecolor=color, edgecolor="none", alpha=alpha, zorder=zorder
            )
        ]
    if box:
        xmin, ymin, xmax, ymax = _box_bounds(
            geometry.shadow_box(spec.shape.parts, pose, half_widths)
        )
        artists.append(
            ax.add_patch(
                Rectangle(
                    (xmin, ymin),
                    xmax - xmin,
                    ymax - ymin,
                    facecolor="none",
                    edgecolor=color,
                    linestyle="--",
                    linewidth=0.9,
                    alpha=0.9,
                    zorder=zorder + 0.1,
                )
            )
        )
    return artists


def draw_initial(ax: Axes, problem: ArrangementProblem, *, shadows: bool = True) -> list[Any]:
    """Draw every object on the table at its nominal initial pose, labelled with its name,
    with its belief shadows from the initial uncertainty. Returns the artists added."""
    artists: list[Any] = []
    for entry in problem.initial:
        spec = problem.object(entry.name)
        color = object_color(problem, entry.name)
        if shadows:
            artists += draw_shadows(ax, spec, entry.pose, entry.uncertainty, color=color)
        artists += draw_object(ax, spec, entry.pose, color=color, label=entry.name, zorder=4)
    return artists


def draw_goal(
    ax: Axes,
    problem: ArrangementProblem,
    *,
    reference_pose: Pose | None = None,
    tolerance: bool = True,
) -> list[Any]:
    """Draw the goal onto ``ax``.

    For an absolute goal: each part's outline at its target pose (dashed, labelled) and,
    translucent, its tolerance region: the shadow of the target pose +- the goal tolerance (a
    full turn when any angle is acceptable), with the tolerance box of the part's centre.

    For a relative goal the targets are poses in the reference part's frame, so they are drawn
    around ``reference_pose``: the reference part's world pose (for instance where a plan left
    it). Without ``reference_pose`` the arrangement is drawn with the reference at the origin,
    the way :func:`draw_problem` draws it in a panel of its own. Returns the artists added.
    """
    if problem.goal.is_relative:
        artists = draw_relative_goal(
            ax, problem, reference_pose=reference_pose or (0.0, 0.0, 0.0), tolerance=tolerance
        )
        return clip_to_table(ax, problem, artists) if reference_pose is not None else artists
    artists = []
    for name, target in problem.goal.targets:
        artists += _draw_target(ax, problem, name, target, tolerance=tolerance)
    return clip_to_table(ax, problem, artists)


def clip_to_table(ax: Axes, problem: ArrangementProblem, artists: list[Any]) -> list[Any]:
    """Clip ``artists`` to the table's surface, so a goal region that reaches past an edge
    stops at the wall (no part can be there). Returns ``artists``."""
    width, depth = problem.table.size
    surface = Rectangle((0.0, 0.0), width, depth, transform=ax.transData)
    for artist in artists:
        artist.set_clip_path(surface)
    return artists


def _draw_target(
    ax: Axes, problem: ArrangementProblem, name: str, target: Pose, *, tolerance: bool
) -> list[Any]:
    spec = problem.object(name)
    color = object_color(problem, name)
    half = goal_tolerance_half_widths(problem)
    artists: list[Any] = []
    if tolerance:
        artists += draw_shadows(
            ax, spec, target, half, color=color, box=False, alpha=TOLERANCE_ALPHA, zorder=1.5
        )
        dx, dy, _ = half
        if dx > 0 or dy > 0:
            artists.append(
                ax.add_patch(
                    Rectangle(
                        (target[0] - dx, target[1] - dy),
                        2 * dx,
                        2 * dy,
                        facecolor="none",
                        edgecolor=color,
                        linewidth=0.9,
                        zorder=3.4,
                    )
                )
            )
    artists += draw_object(ax, spec, target, color=color, fill=False, linestyle="--", zorder=3.5)
    artists += ax.plot(target[0], target[1], marker="+", color=color, markersize=5, zorder=3.6)
    # the name just below the centre's tolerance box, inside the target outline
    artists.append(
        ax.text(
            target[0],
            target[1] - goal_tolerance_half_widths(problem)[1] - 0.04,
            name,
            ha="center",
            va="top",
            fontsize=9,
            fontstyle="italic",
            fontweight="bold",
            color=color,
            zorder=3.7,
        )
    )
    return artists


def draw_relative_goal(
    ax: Axes,
    problem: ArrangementProblem,
    *,
    reference_pose: Pose = (0.0, 0.0, 0.0),
    tolerance: bool = True,
    title: bool = True,
) -> list[Any]:
    """Draw a relative goal: the reference part (filled) at ``reference_pose`` and every other
    goal part at its relative pose (dashed, with its tolerance region, which is taken in the
    reference's frame and drawn here for an exact reference pose).

    With ``title`` the axes get the title ``relative goal (reference: NAME)``.
    """
    goal = problem.goal
    if goal.reference is None:
        raise ValueError(f"problem {problem.name!r} has an absolute goal")
    reference = problem.object(goal.reference)
    artists = draw_object(
        ax,
        reference,
        reference_pose,
        color=object_color(problem, goal.reference),
        alpha=0.85,
        label=goal.reference,
        zorder=3,
    )
    for name, relative in goal.targets:
        artists += _draw_target(
            ax, problem, name, compose(reference_pose, relative), tolerance=tolerance
        )
    if title:
        ax.set_title(f"relative goal (reference: {goal.reference})", fontsize=10)
    return artists


def off_table_note(problem: ArrangementProblem) -> str:
    """A few lines naming what starts off the table: parts (placed by the robot), and the
    manipulators and fixtures the planner may use."""
    on_table = {entry.name for entry in problem.initial}
    lines = []
    parts = [spec.name for spec in problem.parts if spec.name not in on_table]
    if parts:
        lines.append("off table: " + ", ".join(parts))
    for kind, title in ((ObjectKind.MANIPULATOR, "manipulator"), (ObjectKind.FIXTURE, "fixture")):
        specs = [s for s in problem.of_kind(kind) if s.name not in on_table]
        for spec in specs:
            lines.append(f"{title}: {spec.name} ({_describe_shape(spec, problem.units)})")
    return "\n".join(lines)


def draw_legend(ax: Axes, problem: ArrangementProblem, **kwargs: Any) -> Any:
    """A legend explaining the layers present in ``problem``'s picture (proxy artists, so it
    works whatever was drawn). ``kwargs`` go to ``ax.legend``."""
    sample = PART_COLORS[0]
    handles: list[Any] = []
    if problem.table.walls:
        handles.append(Patch(facecolor=WALL_COLOR, label="wall"))
    if len(problem.table.walls) < 4:
        handles.append(
            Line2D([], [], color=TABLE_EDGE, linestyle="--", label="open edge (falls off)")
        )
    if problem.obstacles:
        handles.append(Patch(facecolor=OBSTACLE_COLOR, edgecolor="black", label="obstacle"))
    on_table = {problem.object(entry.name).kind for entry in problem.initial}
    if ObjectKind.FIXTURE in on_table:
        handles.append(Patch(facecolor=FIXTURE_COLOR, edgecolor="black", label="fixture"))
    if ObjectKind.MANIPULATOR in on_table:
        handles.append(Patch(facecolor=MANIPULATOR_COLOR, edgecolor="black", label="manipulator"))
    if problem.initial:
        handles.append(Patch(facecolor=sample, edgecolor="black", label="nominal initial pose"))
        if any(not _is_zero(e.uncertainty) for e in problem.initial):
            handles.append(
                Patch(facecolor=sample, alpha=SHADOW_ALPHA + 0.1, label="belief shadow (hull)")
            )
            handles.append(
                Line2D([], [], color=sample, linestyle="--", linewidth=0.9, label="shadow box")
            )
    handles.append(Line2D([], [], color=sample, linestyle="--", linewidth=1.6, label="goal target"))
    handles.append(
        Patch(facecolor=sample, alpha=TOLERANCE_ALPHA + 0.1, label="goal tolerance region")
    )
    handles.append(
        Line2D(
            [],
            [],
            color=sample,
            marker="s",
            markerfacecolor="none",
            linestyle="none",
            label="goal centre +- tolerance",
        )
    )
    kwargs.setdefault("fontsize", 8)
    kwargs.setdefault("framealpha", 0.95)
    return ax.legend(handles=handles, **kwargs)


# ---------------------------------------------------------------------------------------------
# the whole picture
# ---------------------------------------------------------------------------------------------
def _limits(boxes: Iterable[tuple[float, float, float, float]], margin: float) -> Any:
    xs0, ys0, xs1, ys1 = zip(*boxes, strict=True)
    return (min(xs0) - margin, max(xs1) + margin), (min(ys0) - margin, max(ys1) + margin)


def _problem_bounds(problem: ArrangementProblem) -> list[tuple[float, float, float, float]]:
    """Boxes everything on the table picture fits in: table, walls, shadows, goal regions."""
    width, depth = problem.table.size
    pad = WALL_DRAW_THICKNESS
    boxes = [(-pad, -pad, width + pad, depth + pad)]
    for entry in problem.initial:
        parts = problem.object(entry.name).shape.parts
        boxes.append(_box_bounds(geometry.shadow_box(parts, entry.pose, entry.uncertainty)))
    if not problem.goal.is_relative:
        half = goal_tolerance_half_widths(problem)
        for name, target in problem.goal.targets:
            parts = problem.object(name).shape.parts
            boxes.append(_box_bounds(geometry.shadow_box(parts, target, half)))
    return boxes


def _relative_bounds(problem: ArrangementProblem) -> list[tuple[float, float, float, float]]:
    goal = problem.goal
    assert goal.reference is not None
    reference = problem.object(goal.reference).shape.parts
    boxes = [_box_bounds(geometry.box_of(geometry.footprint(reference, (0.0, 0.0, 0.0))))]
    half = goal_tolerance_half_widths(problem)
    for name, relative in goal.targets:
        parts = problem.object(name).shape.parts
        boxes.append(_box_bounds(geometry.shadow_box(parts, relative, half)))
    return boxes


class _UnitLocator(MaxNLocator):
    """Ticks at round values of a length unit on axes drawn in inches (``factor`` inches per
    unit)."""

    def __init__(self, factor: float) -> None:
        super().__init__(nbins="auto", steps=[1, 2, 2.5, 5, 10])
        self.factor = factor

    def tick_values(self, vmin: float, vmax: float) -> Any:
        return np.asarray(super().tick_values(vmin / self.factor, vmax / self.factor)) * self.factor


def unit_axes(ax: Axes, units: Units, xlabel: str = "x", ylabel: str = "y") -> None:
    """Label ``ax`` (drawn in inches) ``xlabel (unit)`` and ``ylabel (unit)`` in ``units``'
    length unit, ticked at round values of that unit (inches keep matplotlib's own ticks)."""
    ax.set_xlabel(f"{xlabel} ({units.length})")
    ax.set_ylabel(f"{ylabel} ({units.length})")
    if units.length == "in":
        return
    factor = units.length_factor
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_locator(_UnitLocator(factor))
        axis.set_major_formatter(
            FuncFormatter(lambda v, _: f"{round(v / factor, 9) + 0.0:g}".replace("-", "\u2212"))
        )


def _style_axes(ax: Axes, xlim: Any, ylim: Any, units: Units, what: str = "") -> None:
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_aspect("equal")
    unit_axes(ax, units, f"x{what}", f"y{what}")
    ax.grid(True, linewidth=0.3, alpha=0.5)
    ax.set_axisbelow(True)


def problem_figure(problem: ArrangementProblem, *, title: str | None = None) -> Figure:
    """The figure :func:`draw_problem` saves, for callers that want to add to it or show it.

    The caller owns the figure (close it with ``matplotlib.pyplot.close(fig)``).
    """
    plt = pyplot()

    relative = problem.goal.is_relative
    (x0, x1), (y0, y1) = _limits(_problem_bounds(problem), 0.4)
    table_w = 6.0 * (x1 - x0) / max(x1 - x0, (y1 - y0) * 1.4)
    table_h = table_w * (y1 - y0) / (x1 - x0)
    if relative:
        (rx0, rx1), (ry0, ry1) = _limits(_relative_bounds(problem), 0.6)
        # the goal panel at the table's scale, so the arrangement is shown at true size
        scale = table_w / (x1 - x0)
        goal_w = max(2.5, (rx1 - rx0) * scale)
        fig, (ax, goal_ax) = plt.subplots(
            1,
            2,
            layout="constrained",
            figsize=(table_w + goal_w + 3.2, max(table_h, (ry1 - ry0) * scale) + 1.1),
            gridspec_kw={"width_ratios": [table_w, goal_w]},
        )
    else:
        fig, ax = plt.subplots(figsize=(table_w + 3.2, table_h + 1.2), layout="constrained")
        goal_ax = None

    draw_table(ax, problem)
    draw_initial(ax, problem)
    if goal_ax is None:
        draw_goal(ax, problem)
        ax.set_title("start and goal", fontsize=10)
    else:
        draw_relative_goal(goal_ax, problem)
        frame = f" in {problem.goal.reference}'s frame"
        _style_axes(goal_ax, (rx0, rx1), (ry0, ry1), problem.units, frame)
        ax.set_title("start", fontsize=10)
    _style_axes(ax, (x0, x1), (y0, y1), problem.units)

    side = goal_ax if goal_ax is not None else ax
    legend = draw_legend(side, problem, loc="upper left", bbox_to_anchor=(1.03, 1.0))
    note = off_table_note(problem)
    tol = problem.goal.tolerance
    units = problem.units
    length = [f"+-{units.length_out(v):.3g} {units.length}" for v in tol[:2]]
    tol_text = f"goal tolerance: {length[0]}, {length[1]}, " + (
        "any angle" if tol[2] is None else f"+-{units.angle_out(tol[2]):.3g} {units.angle}"
    )
    note = f"{note}\n{tol_text}" if note else tol_text
    # under the legend, whatever its height: a note anchored to the axes' foot would sit
    # under a legend taller than the axes
    side.annotate(
        note,
        xy=(0.0, 0.0),
        xycoords=legend,
        xytext=(0.0, -6.0),
        textcoords="offset points",
        ha="left",
        va="top",
        fontsize=8,
        family="monospace",
        bbox={"boxstyle": "round", "facecolor": "white", "edgecolor": "#bbbbbb"},
    )
    legend.set_zorder(10)

    heading = title if title is not None else problem.name
    summary = first_sentence(problem.description)
    fig.suptitle(heading, fontsize=13, fontweight="bold")
    if summary and title is None:
        fig.supxlabel(summary, fontsize=9, style="italic")
    return fig


def draw_problem(
    problem: ArrangementProblem,
    output: str | Path,
    *,
    title: str | None = None,
    dpi: int = 150,
) -> Path:
    """Draw ``problem`` and save it at ``output`` in the format its suffix names (PNG, SVG or
    PDF: :func:`~arrange_up.figures.backend.figure_format`); returns the path written.

    The picture shows the table with its walls and obstacles, every object on the table at its
    nominal initial pose (filled, labelled) with its belief shadows, and the goal: for an
    absolute goal each part's target outline (dashed) and tolerance region on the table; for a
    relative goal a panel beside the table with the reference part at the origin and the other
    parts at their relative poses. Objects that start off the table are listed in a side note.
    ``title`` replaces the default title (the problem's name and first sentence).
    """
    plt = pyplot()
    fig = problem_figure(problem, title=title)
    try:
        return save_figure(fig, output, dpi=dpi, bbox_inches="tight")
    finally:
        plt.close(fig)


# ---------------------------------------------------------------------------------------------
# fixture-placement heatmap (thesis Figure 4-11)
# ---------------------------------------------------------------------------------------------
#: Colour map of candidate scores (0, the best, is its low end: cyan; 1 is magenta).
HEATMAP_CMAP = "cool"
BLOCKED_COLOR = "#d62728"
#: Half-length (inches) of the short bar that marks a candidate placement's pose and direction.
HEATMAP_MARK = 0.17
INVALID_FACE = "white"


def draw_heatmap(
    ax: Axes,
    problem: ArrangementProblem,
    scores: Any,
    *,
    particles: bool = True,
    blocked: bool = True,
    footprints: bool = False,
    cmap: str = HEATMAP_CMAP,
    colorbar: bool = True,
) -> list[Any]:
    """Draw the candidate placements of one push coloured by score (thesis Figure 4-11).

    ``scores`` is a :class:`arrange_up.repair.StepScores`
    (:func:`arrange_up.repair.step_scores`
    computes it). Drawn: the table; the nominal state before the push (parts filled, faded) and
    after it (dashed outlines); with ``particles`` every particle's parts as faint outlines;
    the part motion swaths (dotted boxes); the paddle at its approach pose with an arrow over
    the nominal push distance; and every candidate placement of the placement stage:

    * valid: a short bar along the fixture's long axis at its commanded pose
      (``footprints=True``: its whole footprint, translucent), coloured by its min-max
      normalised score with ``cmap`` (0, the closest to the nominal next state, is the low
      end);
    * invalid (some particle's push failed: pushed off the table, not at rest): white with a
      grey edge, as the thesis draws them;
    * blocked by the place precondition (``blocked``): a thin red cross;
    * the winner of the one-step problem (if it places a fixture) as a thick black outline.

    Returns the artists added (the colour bar's axes excluded).
    """
    artists: list[Any] = list(draw_table(ax, problem))
    colors = {p.name: object_color(problem, p.name) for p in problem.parts}
    before = scores.nominal_state.as_dict()
    after = scores.nominal_next.as_dict()
    for name, pose in before.items():
        spec = problem.object(name)
        if spec.kind is ObjectKind.PART:
            artists += draw_object(
                ax, spec, pose, color=colors[name], alpha=0.45, label=name, zorder=3
            )
    if particles:
        for state in scores.belief.particles:
            for name, pose in state.poses:
                spec = problem.object(name)
                if spec.kind is not ObjectKind.PART:
                    continue
                artists += draw_object(
                    ax,
                    spec,
                    pose,
                    color=colors[name],
                    fill=False,
                    alpha=0.12,
                    linewidth=0.5,
                    zorder=2.5,
                )
    for name, pose in after.items():
        spec = problem.object(name)
        if spec.kind is ObjectKind.PART:
            artists += draw_object(
                ax, spec, pose, color=colors[name], fill=False, linestyle="--", zorder=3.6
            )
    for name, (x0, y0, x1, y1) in scores.swaths:
        artists += ax.plot(
            [x0, x1, x1, x0, x0],
            [y0, y0, y1, y1, y0],
            color=colors.get(name, "black"),
            linestyle=":",
            linewidth=1.2,
            zorder=3.2,
        )
    # the paddle (backed-off approach) and the nominal push
    push = scores.push
    paddle = problem.object(push.manipulator)
    best = scores.best
    approach = best.push if best is not None and best.push is not None else push
    artists += draw_object(ax, paddle, approach.pose, color=MANIPULATOR_COLOR, zorder=4)
    ux, uy = rotate(paddle.push_direction, approach.pose[2])
    length = push.distance + scores.backoff
    artists.append(
        ax.annotate(
            "",
            xy=(approach.pose[0] + ux * length, approach.pose[1] + uy * length),
            xytext=(approach.pose[0], approach.pose[1]),
            arrowprops={"arrowstyle": "->", "color": MANIPULATOR_COLOR, "linewidth": 1.4},
            zorder=4.1,
        )
    )

    norm = Normalize(0.0, 1.0)
    colormap = colormaps[cmap]
    placements = [c for c in scores.placements if c.fixture is not None and c.pose is not None]
    # worst first, so the best end up on top
    order = sorted(
        placements,
        key=lambda c: (
            {"blocked": 0, "invalid": 1}.get(c.status, 2),
            -(c.score if c.score is not None else 0.0),
        ),
    )
    for cand in order:
        spec = problem.object(cand.fixture)
        x, y, theta = cand.pose
        if cand.status == "blocked":
            if blocked:
                artists += ax.plot(
                    x, y, marker="x", color=BLOCKED_COLOR, markersize=3, alpha=0.5, zorder=3.3
                )
            continue
        if cand.status == "ok":
            color = colormap(norm(cand.score if cand.score is not None else 0.0))
            edge = "none"
        else:
            color, edge = INVALID_FACE, "#777777"
        if footprints:
            artists += [
                ax.add_patch(p)
                for p in _polygon_patches(
                    geometry.footprint(spec.shape.parts, cand.pose),
                    facecolor=color,
                    edgecolor=edge if edge != "none" else color,
                    alpha=0.55,
                    linewidth=0.5,
                    zorder=3.4,
                )
            ]
        else:
            xmin, ymin, xmax, ymax = spec.shape.extent
            half = HEATMAP_MARK
            along = 0.0 if (xmax - xmin) >= (ymax - ymin) else 0.5 * math.pi
            dx, dy = half * math.cos(theta + along), half * math.sin(theta + along)
            # An outlined bar: the edge colour drawn wider underneath the fill colour.
            strokes = [(edge, 4.2, 3.4)] if edge != "none" else []
            for stroke, width, z in strokes + [(color, 3.0, 3.45)]:
                artists += ax.plot(
                    [x - dx, x + dx],
                    [y - dy, y + dy],
                    color=stroke,
                    linewidth=width,
                    solid_capstyle="butt",
                    zorder=z,
                )
    if best is not None and best.fixture is not None and best.pose is not None:
        spec = problem.object(best.fixture)
        artists += draw_object(
            ax,
            spec,
            best.pose,
            color="black",
            fill=False,
            linewidth=1.6,
            label="best",
            label_size=7,
            zorder=4.5,
        )
    if colorbar:
        mappable = ScalarMappable(norm=norm, cmap=colormap)
        mappable.set_array(np.array([]))
        bar = ax.figure.colorbar(mappable, ax=ax, shrink=0.8, pad=0.02)
        bar.set_label("normalised distance to the nominal next state (0 = best)", fontsize=8)
    return artists


def heatmap_figure(
    problem: ArrangementProblem, scores: Any, *, title: str | None = None, **kwargs: Any
) -> Figure:
    """A figure with :func:`draw_heatmap` of ``scores`` and a summary; ``kwargs`` go to
    :func:`draw_heatmap`. The caller owns the figure (close it with ``plt.close(fig)``)."""
    plt = pyplot()
    width, depth = problem.table.size
    fig, ax = plt.subplots(
        figsize=(8.8, 7.0 * depth / max(width, 1e-9) + 0.6), layout="constrained"
    )
    draw_heatmap(ax, problem, scores, **kwargs)
    pad = WALL_DRAW_THICKNESS + 0.3
    boxes = [(-pad, -pad, width + pad, depth + pad)] + [box for _, box in scores.swaths]
    (x0, x1), (y0, y1) = _limits(boxes, 0.2)
    _style_axes(
        ax,
        (max(x0, -3.0), min(x1, width + 3.0)),
        (max(y0, -3.0), min(y1, depth + 3.0)),
        problem.units,
    )
    placements = [c for c in scores.placements if c.fixture is not None]
    counts = {k: sum(1 for c in placements if c.status == k) for k in ("ok", "invalid", "blocked")}
    bare = scores.no_fixture
    bare_text = (
        f"no fixture: score {bare.score:.3g}, distance "
        f"{problem.units.length_out(bare.distance):.3g} {problem.units.length}"
        if bare.valid and bare.score is not None
        else f"no fixture: invalid ({bare.reason})"
    )
    best = scores.best
    if best is None:
        choice = "every candidate is invalid"
    elif best.fixture is None:
        choice = f"chosen: no fixture, push x{best.multiplier:g}"
    else:
        choice = f"chosen: {best.fixture} (outlined), push x{best.multiplier:g}"
    ax.set_title(
        title
        or (
            f"{problem.name}: step {scores.step + 1}, candidates at "
            f"{scores.selection_multiplier:g}x the push ({scores.method}, "
            f"{len(scores.belief)} particles)"
        ),
        fontsize=10,
    )
    ax.text(
        0.01,
        0.01,
        f"{counts['ok']} valid, {counts['invalid']} invalid (white), {counts['blocked']} "
        f"blocked (x)\n{bare_text}\n{choice}",
        transform=ax.transAxes,
        fontsize=7.5,
        family="monospace",
        va="bottom",
        bbox={"boxstyle": "round", "facecolor": "white", "edgecolor": "#bbbbbb", "alpha": 0.9},
        zorder=6,
    )
    handles = [
        Patch(facecolor=INVALID_FACE, edgecolor="#777777", label="invalid outcome"),
        Line2D([], [], marker="x", color=BLOCKED_COLOR, linestyle="none", label="blocked"),
        Line2D([], [], color="black", linestyle=":", label="part motion swath"),
        Line2D([], [], color="black", linestyle="--", label="nominal next state"),
    ]
    ax.legend(handles=handles, loc="upper right", fontsize=7, framealpha=0.9).set_zorder(6)
    return fig


def write_heatmap(
    problem: ArrangementProblem,
    scores: Any,
    output: str | Path,
    *,
    dpi: int = 150,
    title: str | None = None,
    **kwargs: Any,
) -> Path:
    """Save :func:`heatmap_figure` of ``scores`` at ``output`` (PNG, SVG or PDF, by its
    suffix); returns the path."""
    plt = pyplot()
    fig = heatmap_figure(problem, scores, title=title, **kwargs)
    try:
        return save_figure(fig, output, dpi=dpi, bbox_inches="tight")
    finally:
        plt.close(fig)
