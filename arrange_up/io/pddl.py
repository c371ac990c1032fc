"""The PDDL front end: arrangement problems as standard PDDL 2.1 problems.

A ``.pddl`` problem is plain PDDL 2.1 (``:typing``, ``:negative-preconditions``,
``:numeric-fluents``) over one shared domain, ``semantics/arrange-up-domain.pddl``, which
unified-planning's ``PDDLReader`` parses unchanged. The vocabulary:

**Types.** ``movable`` (``placeable`` = ``part``, ``fixture``; ``manipulator``) and
``obstacle``, and below them the *shape types* of the catalogue ``semantics/shapes.yaml``
(``block-1x1``, ``tee``, ``paddle-short``, ``short-bar``, ...; see
:mod:`arrange_up.io.shape_catalogue`). Every object is typed by a shape type, which gives both its
kind and its geometry.

**Functions** (numeric fluents; lengths in inches, angles in degrees):

* ``(x ?o)``, ``(y ?o)``, ``(theta ?o)``: the nominal initial pose of an object on the table
  (and the fixed pose of an obstacle); ``theta`` defaults to 0.
* ``(dx ?o)``, ``(dy ?o)``, ``(dtheta ?o)``: the half-widths of its initial uncertainty
  (default 0).
* ``(rel-x ?p ?r)``, ``(rel-y ?p ?r)``, ``(rel-theta ?p ?r)``: the pose of part ``?p`` in the
  frame of part ``?r``, for relative goals.
* 0-ary: ``(table-width)``, ``(table-depth)`` (required); ``(place-dx)``, ``(place-dy)``,
  ``(place-dtheta)``, ``(push-dx)``, ``(push-dy)``, ``(push-dtheta)`` (action noise
  half-widths); ``(friction-min)``, ``(friction-max)``, ``(part-density-min)``,
  ``(part-density-max)``, ``(manipulator-density-min)``, ``(manipulator-density-max)``
  (uniform ranges; densities in mass per square inch). Omitted ones take the defaults of
  :class:`~arrange_up.model.problem.Uncertainty` (no noise, nominal parameters).

**Predicates.** ``(on-table ?o)``: the object starts on the table (objects not listed start
off it); ``(wall-left)``, ``(wall-right)``, ``(wall-bottom)``, ``(wall-top)``: rigid walls (PDDL's
closed world: an edge without its predicate has no wall).

**Goals** are one conjunction of ``(on-table P)`` and interval conditions, both bounds per
dimension: ``(>= (x P) lo) (<= (x P) hi)`` and likewise ``y`` and, unless any angle will do,
``theta``; or, for a relative goal, the same on ``(rel-x P R)``, ``(rel-y P R)``,
``(rel-theta P R)`` with one reference part ``R``. Every goal part must have the same
half-widths (the problem has one tolerance). Angles are understood modulo the part's rotational
symmetry (a square block turned 90 degrees is the same block). The goal also states the
format's put-away rule: ``(not (on-table F))`` for each fixture ``F`` that starts off the table
(it must end off it: a fence put down is picked up). The rule holds whether a file states it
or not (a file written before it was stated reads as before); the reader refuses
``(not (on-table X))`` for anything else (a part, or a fixture that starts on the table, which
may stay) and ``(on-table F)`` for such a fixture.

**Units.** PDDL files are always in **inches and degrees** (the YAML format's defaults; degrees
keep angles like 15 or 90 exact). Numbers are read exactly (``Fraction``) and converted once.
A negative number is written the standard way, ``(- 15)`` (PDDL's numbers are unsigned, and
strict parsers refuse ``-15``); the reader takes both forms.

**Files written by unified-planning's PDDLWriter** from a problem ``PDDLReader`` read (problem
``NAME-problem`` of domain ``NAME-domain``) are read as problem ``NAME`` of the arrange-up
domain. PDDLWriter's output for the model of :func:`arrange_up.up.compile.to_up` is not (that
model has no shapes); the refusal says to write the problem with :func:`write_pddl_problem`.

**Names** are kept as written: unified-planning lowercases PDDL names (PDDL is
case-insensitive), so :func:`load_pddl_problem` restores the case from the file's ``:objects``
and problem name. Object names must not repeat a type, function, predicate or action name
(unified-planning refuses that), nor differ from each other only in case.

**What PDDL cannot express** (:func:`write_pddl_problem` raises :class:`PddlExportError`):
shapes that are not in the catalogue (or a catalogue shape with another kind), planning hints
(``planning:``), names that are not PDDL names or that clash as above. The actions' real
parameters and their physical effects are not in PDDL either: the domain declares place, push
and pick with their symbolic preconditions only (see its comments); the effects come from the
semantics (:mod:`arrange_up.up.compile`).

The vocabulary and the domain are :mod:`arrange_up.io.pddl_domain`, the writer
:mod:`arrange_up.io.pddl_writer`, the reader :mod:`arrange_up.io.pddl_reader`; this module
gathers their public functions.
"""

from __future__ import annotations

from arrange_up.io.pddl_domain import DOMAIN_FILE, DOMAIN_NAME, domain_path, domain_pddl_text
from arrange_up.io.pddl_reader import (
    check_pddl_problem,
    check_pddl_problem_text,
    load_pddl_problem,
    load_pddl_problem_text,
    problem_from_up,
)
from arrange_up.io.pddl_writer import PddlExportError, write_pddl_problem

__all__ = [
    "DOMAIN_FILE",
    "DOMAIN_NAME",
    "PddlExportError",
    "check_pddl_problem",
    "check_pddl_problem_text",
    "domain_path",
    "domain_pddl_text",
    "load_pddl_problem",
    "load_pddl_problem_text",
    "problem_from_up",
    "write_pddl_problem",
]
