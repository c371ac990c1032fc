"""Writing an :class:`~arrange_up.model.problem.ArrangementProblem` as a PDDL problem of the
arrange-up domain (see :mod:`arrange_up.io.pddl` for the vocabulary and what PDDL cannot
express)."""

from __future__ import annotations

import textwrap
from collections.abc import Iterable
from decimal import Decimal
from typing import Any

from arrange_up.io.pddl_domain import (
    DOMAIN_FILE,
    DOMAIN_NAME,
    NOISE_FUNCTIONS,
    PDDL_UNITS,
    POSE_FUNCTIONS,
    RELATIVE_FUNCTIONS,
    VOCABULARY,
    decimal_text,
    num,
    number_term,
)
from arrange_up.io.shape_catalogue import PDDL_NAME, Catalogue, load_catalogue
from arrange_up.model.problem import DEFAULT_CONTROLLER, ArrangementProblem, PlanningHints
from arrange_up.model.units import Units

__all__ = ["PddlExportError", "write_pddl_problem"]


class PddlExportError(ValueError):
    """A problem that PDDL cannot express. ``reasons`` lists every obstacle found; ``str()``
    names the problem and each reason."""

    def __init__(self, problem: str, reasons: Iterable[str]) -> None:
        self.problem = problem
        self.reasons = tuple(reasons)
        lines = "\n".join(f"  - {r}" for r in self.reasons)
        super().__init__(f"problem {problem!r} cannot be written as PDDL:\n{lines}")


def write_pddl_problem(problem: ArrangementProblem, catalogue: Catalogue | None = None) -> str:
    """The PDDL text of ``problem`` (inches and degrees; see :mod:`arrange_up.io.pddl`).

    Raises :class:`PddlExportError` listing everything PDDL cannot express.

    >>> from arrange_up.io.domains import load
    >>> text = write_pddl_problem(load("blocks-1"))
    >>> "(:domain arrange-up)" in text and "A - block-1x1" in text
    True
    """
    catalogue = catalogue if catalogue is not None else load_catalogue()
    reasons: list[str] = []
    if not PDDL_NAME.fullmatch(problem.name):
        reasons.append(
            f"the problem name {problem.name!r} is not a PDDL name (a letter, then letters, "
            "digits, '-' or '_')"
        )
    types: dict[str, str] = {}
    seen: dict[str, str] = {}
    type_names = {t.lower() for t in catalogue.type_names}
    for spec in problem.objects:
        key = spec.name.lower()
        if not PDDL_NAME.fullmatch(spec.name):
            reasons.append(
                f"object {spec.name!r}: not a PDDL name (a letter, then letters, digits, '-' "
                "or '_')"
            )
        elif key in VOCABULARY or key in type_names:
            reasons.append(
                f"object {spec.name!r}: the name is taken by the PDDL vocabulary (a type, "
                "function, predicate or action of the arrange-up domain); unified-planning "
                "refuses an object named like one"
            )
        elif key in seen:
            reasons.append(
                f"objects {seen[key]!r} and {spec.name!r}: names differ only in case, which "
                "PDDL (case-insensitive) cannot tell apart"
            )
        seen.setdefault(key, spec.name)
        entry = catalogue.match(spec.kind, spec.shape)
        if entry is None:
            known = ", ".join(e.type_name for e in catalogue.of_kind(spec.kind)) or "none"
            reasons.append(
                f"object {spec.name!r}: its shape ({_describe_shape(spec.shape, problem.units)}) "
                f"is not {spec.kind.with_article} shape of the catalogue {catalogue.path} (its "
                f"{spec.kind.value} types: {known}); add it there to write this problem as "
                "PDDL"
            )
        else:
            types[spec.name] = entry.type_name
    if problem.planning != PlanningHints():
        used = [
            name
            for name in (
                "place_offsets",
                "place_angles",
                "push_distances",
                "push_directions",
                "max_nodes",
            )
            if getattr(problem.planning, name) is not None
        ]
        reasons.append(
            f"planning hints ({', '.join('planning.' + u for u in used)}): PDDL has no place "
            "for them"
        )
    if problem.controller != DEFAULT_CONTROLLER:
        reasons.append(
            f"the push controller (controller: kind {problem.controller.kind.value}, or gains "
            "other than the defaults): PDDL has no place for it, and a PDDL problem is driven by "
            "the default compliant controller"
        )
    goal = problem.goal
    if goal.tolerance[2] is None and any(pose[2] != 0 for _, pose in goal.targets):
        reasons.append(
            "the goal allows any angle but its targets give angles: PDDL states no theta "
            "condition then, so it cannot carry them (set the target angles to 0)"
        )
    if reasons:
        raise PddlExportError(problem.name, reasons)
    return _render(problem, types)


def _render(problem: ArrangementProblem, types: dict[str, str]) -> str:
    deg = PDDL_UNITS.angle_out
    lines = [
        f"; {problem.name}: an arrange-up problem in PDDL 2.1 for the domain "
        f"{DOMAIN_NAME} ({DOMAIN_FILE}).",
        "; Units: inches and degrees. Written by arrange_up.io.pddl.write_pddl_problem.",
    ]
    if problem.description:
        lines += _comment_block("description: " + " ".join(problem.description.split()))
    lines += [f"(define (problem {problem.name})", f"  (:domain {DOMAIN_NAME})", "  (:objects"]
    lines += [f"    {spec.name} - {types[spec.name]}" for spec in problem.objects]
    lines += ["  )", "  (:init"]
    table = problem.table
    walls = ", ".join(table.walls) if table.walls else "none"
    lines.append(f"    ; the table, {num(table.width)} x {num(table.depth)} in; walls: {walls}")
    lines.append(
        f"    (= (table-width) {_term(table.width)}) (= (table-depth) {_term(table.depth)})"
    )
    if table.walls:
        lines.append("    " + " ".join(f"(wall-{edge})" for edge in table.walls))
    unc = problem.uncertainty
    lines.append("    ; action noise (half-widths) and domain parameter ranges")
    noise = []
    for name, (attr, index) in NOISE_FUNCTIONS.items():
        value = getattr(unc, attr)[index]
        noise.append(f"(= ({name}) {_term(deg(value) if name.endswith('theta') else value)})")
    lines += ["    " + " ".join(noise[:3]), "    " + " ".join(noise[3:6])]
    lines += ["    " + " ".join(noise[i : i + 2]) for i in (6, 8, 10)]
    obstacles = problem.obstacles
    if obstacles:
        lines.append("    ; obstacles (fixed)")
        for spec in obstacles:
            assert spec.pose is not None
            lines.append(f"    (on-table {spec.name}) {_pose_facts(spec.name, spec.pose)}")
    if problem.initial:
        lines.append("    ; objects on the table at the start: nominal pose and uncertainty")
        for entry in problem.initial:
            lines.append(f"    (on-table {entry.name}) {_pose_facts(entry.name, entry.pose)}")
            dx, dy, dtheta = entry.uncertainty
            lines.append(
                f"      (= (dx {entry.name}) {_term(dx)}) (= (dy {entry.name}) {_term(dy)}) "
                f"(= (dtheta {entry.name}) {_term(deg(dtheta))})"
            )
    lines += ["  )", "  (:goal (and"]
    goal = problem.goal
    tol_x, tol_y, tol_theta = goal.tolerance
    if goal.reference is not None:
        lines.append(f"    (on-table {goal.reference})")
    for part, (tx, ty, ttheta) in goal.targets:
        if goal.reference is None:
            fx, fy, ftheta = (f"({f} {part})" for f in POSE_FUNCTIONS)
        else:
            fx, fy, ftheta = (f"({f} {part} {goal.reference})" for f in RELATIVE_FUNCTIONS)
        lines.append(f"    (on-table {part})")
        lines.append("    " + _interval(fx, tx, tol_x))
        lines.append("    " + _interval(fy, ty, tol_y))
        if tol_theta is not None:
            lines.append("    " + _interval(ftheta, deg(ttheta), deg(tol_theta)))
    if problem.put_away:
        lines.append(
            "    ; fixtures that start off the table end off it (a fence put down is picked up)"
        )
        lines.append("    " + " ".join(f"(not (on-table {name}))" for name in problem.put_away))
    lines += ["  ))", ")", ""]
    return "\n".join(lines)


def _pose_facts(name: str, pose: tuple[float, float, float]) -> str:
    x, y, theta = pose
    return (
        f"(= (x {name}) {_term(x)}) (= (y {name}) {_term(y)}) "
        f"(= (theta {name}) {_term(PDDL_UNITS.angle_out(theta))})"
    )


def _interval(fluent: str, target: float, tol: float) -> str:
    t, d = Decimal(num(target)), Decimal(num(tol))
    low, high = number_term(decimal_text(t - d)), number_term(decimal_text(t + d))
    return f"(>= {fluent} {low}) (<= {fluent} {high})"


def _term(value: float) -> str:
    return number_term(num(value))


def _comment_block(text: str, width: int = 96) -> list[str]:
    wrapped = textwrap.wrap(text, width=width - 4) or [""]
    return ["; " + wrapped[0]] + [";   " + line for line in wrapped[1:]]


def _describe_shape(shape: Any, units: Units) -> str:
    """The shape for a message: a box's size in the problem's length unit (and in inches, the
    catalogue's, when that is another), or a polygon's name and size of outline."""
    if shape.box is not None:
        width, height = shape.box
        size = f"box {num(width)} x {num(height)} in"
        if units.length != "in":
            out = units.length_out
            size = (
                f"box {out(width):.4g} x {out(height):.4g} {units.length} = "
                f"{width:.4g} x {height:.4g} in"
            )
        return size
    name = f" {shape.name!r}" if shape.name else ""
    vertices = sum(len(p) for p in shape.parts)
    return f"polygon{name} with {vertices} vertices in {len(shape.parts)} convex parts"
