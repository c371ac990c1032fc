"""Load and validate ``.yaml`` problem files (format ``arrange-up/1``).

The format is specified in ``docs/problem-format.md`` (arrange-up's own ``planning:`` and
``controller:`` keys in ``docs/problem-format-planner.md``, every check and message in
``docs/problem-format-checks.md``). This module turns a file into an
:class:`~arrange_up.model.problem.ArrangementProblem` or refuses it with a
:class:`~arrange_up.model.errors.ProblemFormatError` that lists *every* problem found in the file,
each naming the file, the 1-based line and column where the offending YAML node starts, the key
path (``objects.T.shape``, ``initial.C.pose[2]``) and what was expected. A file is never
half-loaded: a problem is built only when the whole file is valid.

The reading of YAML with positions and the diagnostics are :mod:`arrange_up.io.yaml_source`,
the builder of the problem, section by section, :mod:`arrange_up.io.yaml_builder`; the placement
checks (footprints on the table, no overlaps) are :mod:`arrange_up.io.validation`, shared with
the PDDL reader.

Public functions:

* :func:`load_problem` / :func:`load_problem_text`: the problem, or ``ProblemFormatError``
  (which carries the errors and, for context, any warnings). Warnings alone never refuse a file.
* :func:`check_problem`: the problem (or ``None``) and every diagnostic, warnings included,
  for ``arrange-up check``.

Semantics beyond the bare format, all enforced here:

* **Units** are converted once: lengths to inches, angles to radians, densities (mass per
  square user length unit) to mass per square inch; friction is dimensionless. The problem keeps
  the file's :class:`~arrange_up.model.units.Units`. Messages quote values in the file's units.
* **Shapes** are given in ``shapes:`` (named) or inline in an object's ``shape:`` as exactly one
  of ``{box: [w, h]}`` (both > 0, centred), ``{polygon: [[x, y], ...]}`` (a simple polygon, may
  be non-convex: decomposed into convex parts) or ``{convex_parts: [[[x, y], ...], ...]}`` (each
  part a valid convex polygon; parts may touch but not overlap). Coordinates are in the
  object's frame; the loader shifts them so the shape's area centroid is the origin, because a
  pose refers to the centroid. Parts are made counter-clockwise. ``Shape.box`` is set for boxes.
* **Objects** have identifier names (``[A-Za-z_][A-Za-z0-9_-]*``), a kind (part, manipulator,
  fixture, obstacle) and a shape. Obstacles need a ``pose`` and appear neither in ``initial`` nor
  in the goal; other kinds must not have a ``pose`` under ``objects``.
* **Initial** entries name declared non-obstacle objects, with a ``pose`` and an optional
  ``uncertainty`` (default ``[0, 0, 0]``, no negative half-widths). ``initial`` itself is
  optional (nothing on the table). The nominal footprints of initial objects and obstacles must
  not overlap (intersection area above ``AREA_TOLERANCE`` square inches; touching is fine) and
  must lie inside the table ``[0, W] x [0, D]`` (within ``BOUNDS_TOLERANCE`` inches).
* **Goal**: exactly one of ``poses`` (absolute) or ``relative`` (``reference`` plus ``poses``);
  at least one target; targets are declared parts; a relative goal's reference is a declared
  part not listed among its own poses. ``tolerance`` is ``[dx, dy]`` (any angle) or
  ``[dx, dy, dtheta]``, all >= 0; when missing, :data:`DEFAULT_GOAL_TOLERANCE_IN` inches in x and
  y and any angle is used, with a warning.
* **Uncertainty**: ``place``/``push`` are three half-widths >= 0; ``friction``,
  ``part_density`` and ``manipulator_density`` are ``[low, high]`` with ``0 <= low <= high``.
  Omitted keys take the defaults of :class:`~arrange_up.model.problem.Uncertainty`.
* **Table**: ``size`` is two positive numbers; ``walls`` a list drawn from left, right, bottom,
  top without repeats (default all four, ``[]`` for none).
* **format** is optional and must be ``arrange-up/1``; **name** is a required non-empty string;
  **description** an optional string.
* **planning** hints: ``place_offsets`` (``[[dx, dy], ...]``, lengths), ``place_angles``
  (angles), ``push_distances`` (positive lengths), ``push_directions`` (a subset of +x, -x, +y,
  -y) and ``max_nodes`` (a positive integer); lists must be non-empty. Unknown keys inside
  ``planning`` are errors, since a typo there would silently change planning.
* **controller**: ``kind`` (``compliant`` or ``servo``; default the problem default) and the
  positive numbers ``kp``, ``kp_angle``, ``speed``, ``force``, ``torque`` (the servo reads only
  ``speed`` and ``force``). Unknown keys are errors, as in ``planning``.
* Unknown keys anywhere else are **warnings** (the format welcomes new optional keys).
* Every number must be a finite real; booleans are not numbers. Duplicate keys are errors,
  reported at each duplicate. Problems are collected through the whole file, but follow-on
  checks are skipped for parts already found invalid (no cascades).
"""

from __future__ import annotations

from pathlib import Path

from arrange_up.io.validation import AREA_TOLERANCE, BOUNDS_TOLERANCE
from arrange_up.io.yaml_builder import (
    DEFAULT_GOAL_TOLERANCE_IN,
    FORMAT_VERSION,
    SUPPORTED_FORMATS,
    ProblemBuilder,
)
from arrange_up.io.yaml_source import Report, parse, read_text, root_node
from arrange_up.model.errors import Diagnostic, ProblemFormatError, sort_diagnostics
from arrange_up.model.problem import ArrangementProblem

__all__ = [
    "AREA_TOLERANCE",
    "BOUNDS_TOLERANCE",
    "DEFAULT_GOAL_TOLERANCE_IN",
    "FORMAT_VERSION",
    "SUPPORTED_FORMATS",
    "check_problem",
    "check_problem_text",
    "load_problem",
    "load_problem_text",
]


def load_problem(path: str | Path) -> ArrangementProblem:
    """Load a ``.yaml`` problem file.

    Raises :class:`ProblemFormatError` listing every problem found in the file (errors, and any
    warnings for context) if the file cannot be read or has at least one error.
    """
    problem, diagnostics = check_problem(path)
    if problem is None:
        raise ProblemFormatError(diagnostics)
    return problem


def load_problem_text(text: str, source: str = "<text>") -> ArrangementProblem:
    """Load a problem from YAML ``text``; ``source`` names it in messages and on the problem."""
    problem, diagnostics = check_problem_text(text, source)
    if problem is None:
        raise ProblemFormatError(diagnostics)
    return problem


def check_problem(path: str | Path) -> tuple[ArrangementProblem | None, list[Diagnostic]]:
    """Validate a problem file: ``(problem, diagnostics)``.

    ``problem`` is ``None`` when there is at least one error. ``diagnostics`` holds errors and
    warnings in file order. Never raises for a bad file.
    """
    source = str(path)
    text, diagnostic = read_text(Path(path), source)
    if diagnostic is not None:
        return None, [diagnostic]
    assert text is not None
    return check_problem_text(text, source)


def check_problem_text(
    text: str, source: str = "<text>"
) -> tuple[ArrangementProblem | None, list[Diagnostic]]:
    """Like :func:`check_problem`, for YAML ``text`` named ``source`` in messages."""
    report = Report(source)
    problem: ArrangementProblem | None = None
    try:
        data = parse(text, report)
        if data is not None:
            problem = ProblemBuilder(report).build(root_node(data))
    except Exception as error:  # a safety net: a bug here must not become a traceback
        report.error(
            None,
            "",
            f"internal error while checking the file ({type(error).__name__}: {error}); "
            "please report this",
        )
    diagnostics = sort_diagnostics(report.diagnostics)
    if any(d.severity == "error" for d in diagnostics):
        return None, diagnostics
    if problem is None:  # pragma: no cover - every refusal records an error
        return None, diagnostics
    return problem, diagnostics
