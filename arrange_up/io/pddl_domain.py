"""The arrange-up PDDL domain: its vocabulary, its text and its shipped file.

The names below are the domain's types, functions, predicates and actions (their meaning is
described in :mod:`arrange_up.io.pddl`); :func:`domain_pddl_text` writes the domain with the
shape types of a catalogue, :func:`domain_path` finds the shipped file, and :func:`num` writes
a number the way every arrange-up PDDL file writes numbers.
"""

from __future__ import annotations

from decimal import Decimal
from pathlib import Path

from arrange_up.io.shape_catalogue import Catalogue, load_catalogue, semantics_dir
from arrange_up.model.problem import WALL_EDGES, ObjectKind
from arrange_up.model.units import Units

__all__ = [
    "ABSTRACT_TYPES",
    "ACTIONS",
    "ANGLE_FUNCTIONS",
    "DOMAIN_FILE",
    "DOMAIN_NAME",
    "NOISE_FUNCTIONS",
    "PDDL_UNITS",
    "POSE_FUNCTIONS",
    "RELATIVE_FUNCTIONS",
    "SPREAD_FUNCTIONS",
    "TABLE_FUNCTIONS",
    "VOCABULARY",
    "WALL_PREDICATES",
    "decimal_text",
    "domain_path",
    "domain_pddl_text",
    "num",
    "number_term",
]

DOMAIN_NAME = "arrange-up"
DOMAIN_FILE = "arrange-up-domain.pddl"
#: The units of every PDDL file.
PDDL_UNITS = Units(length="in", angle="deg")

ABSTRACT_TYPES = ("movable", "placeable", "part", "fixture", "manipulator", "obstacle")
POSE_FUNCTIONS = ("x", "y", "theta")
SPREAD_FUNCTIONS = ("dx", "dy", "dtheta")
RELATIVE_FUNCTIONS = ("rel-x", "rel-y", "rel-theta")
#: 0-ary functions of the uncertainty, with the ``Uncertainty`` field and index they set.
NOISE_FUNCTIONS: dict[str, tuple[str, int]] = {
    "place-dx": ("place", 0),
    "place-dy": ("place", 1),
    "place-dtheta": ("place", 2),
    "push-dx": ("push", 0),
    "push-dy": ("push", 1),
    "push-dtheta": ("push", 2),
    "friction-min": ("friction", 0),
    "friction-max": ("friction", 1),
    "part-density-min": ("part_density", 0),
    "part-density-max": ("part_density", 1),
    "manipulator-density-min": ("manipulator_density", 0),
    "manipulator-density-max": ("manipulator_density", 1),
}
TABLE_FUNCTIONS = ("table-width", "table-depth")
WALL_PREDICATES = {f"wall-{edge}": edge for edge in WALL_EDGES}
ACTIONS = ("place", "push", "pick")
#: Every name the domain defines; objects must not use them (case-insensitively).
VOCABULARY = frozenset(
    ABSTRACT_TYPES
    + POSE_FUNCTIONS
    + SPREAD_FUNCTIONS
    + RELATIVE_FUNCTIONS
    + tuple(NOISE_FUNCTIONS)
    + TABLE_FUNCTIONS
    + tuple(WALL_PREDICATES)
    + ("on-table", "object", "number")
    + ACTIONS
)
ANGLE_FUNCTIONS = ("theta", "dtheta", "rel-theta")


def domain_path() -> Path:
    """The shipped domain file, ``semantics/arrange-up-domain.pddl``."""
    return semantics_dir() / DOMAIN_FILE


def domain_pddl_text(catalogue: Catalogue | None = None) -> str:
    """The text of the shared PDDL domain, with the shape types of ``catalogue`` (default: the
    shipped one). The shipped ``semantics/arrange-up-domain.pddl`` is this text."""
    catalogue = catalogue if catalogue is not None else load_catalogue()
    by_kind = {kind: [e.type_name for e in catalogue.of_kind(kind)] for kind in ObjectKind}
    kind_type = {
        ObjectKind.PART: "part",
        ObjectKind.FIXTURE: "fixture",
        ObjectKind.MANIPULATOR: "manipulator",
        ObjectKind.OBSTACLE: "obstacle",
    }
    shape_lines = [
        f"    {' '.join(names)} - {kind_type[kind]}" for kind, names in by_kind.items() if names
    ]
    return _DOMAIN_TEMPLATE.replace("@SHAPE_TYPES@", "\n".join(shape_lines))


_DOMAIN_TEMPLATE = """\
; The shared action vocabulary of arrange-up problems (PDDL 2.1 with typing and numeric fluents).
;
; Every .pddl problem of arrange-up is a problem of this domain. PDDL 2.1 cannot give an action
; real-valued parameters or effects computed by a physics simulation, so this file declares what
; PDDL can: the types, the functions and predicates that describe a problem, and the three
; actions with their symbolic preconditions. What a place or push does to the poses is defined
; by arrange-up's transition semantics (arrange_up.up.compile.to_up builds the unified-planning
; model with real parameters and simulated effects).
;
; Units: lengths in inches, angles in degrees. Generated from semantics/shapes.yaml by
; arrange_up.io.pddl.domain_pddl_text(); a test keeps this file and the catalogue in step.
(define (domain arrange-up)
  (:requirements :strips :typing :negative-preconditions :numeric-fluents)

  (:types
    ; movable objects can be on or off the table; obstacles are fixed on it
    movable obstacle - object
    placeable manipulator - movable
    part fixture - placeable
    ; shape types (semantics/shapes.yaml): each gives an object its kind and its geometry
@SHAPE_TYPES@
  )

  (:predicates
    (on-table ?o)   ; in :init, the object starts on the table
    (wall-left) (wall-right) (wall-bottom) (wall-top)   ; rigid walls along the table's edges
  )

  (:functions
    ; nominal pose (x, y in inches; theta in degrees) of an object on the table at the start,
    ; or of an obstacle; the pose refers to the shape's area centroid
    (x ?o) (y ?o) (theta ?o)
    ; half-widths of the initial uncertainty: the pose lies in x +- dx, y +- dy, theta +- dtheta
    (dx ?o - movable) (dy ?o - movable) (dtheta ?o - movable)
    ; pose of part ?p in the frame of part ?r (relative goals)
    (rel-x ?p - part ?r - part) (rel-y ?p - part ?r - part) (rel-theta ?p - part ?r - part)
    ; the table [0, table-width] x [0, table-depth], inches
    (table-width) (table-depth)
    ; action noise: a place lands within the target +- these half-widths, a push's approach pose
    ; within the commanded one +- these
    (place-dx) (place-dy) (place-dtheta) (push-dx) (push-dy) (push-dtheta)
    ; domain parameters, drawn uniformly per action (densities in mass per square inch)
    (friction-min) (friction-max)
    (part-density-min) (part-density-max)
    (manipulator-density-min) (manipulator-density-max)
  )

  ; place ?o at a pose (real parameters x, y, theta in the arrange-up model): the object must be
  ; off the table. Where it lands, and what it touches, is up to the semantics.
  (:action place
    :parameters (?o - placeable)
    :precondition (not (on-table ?o))
    :effect (on-table ?o))

  ; push with ?m from an approach pose over a distance (real parameters in the arrange-up
  ; model): the manipulator is put down, driven perpendicular to its long side and lifted off
  ; again, so it must start off the table. Its effect on the poses is the semantics' physics.
  (:action push
    :parameters (?m - manipulator)
    :precondition (not (on-table ?m))
    :effect (and))

  ; pick ?o off the table (no uncertainty)
  (:action pick
    :parameters (?o - movable)
    :precondition (on-table ?o)
    :effect (not (on-table ?o)))
)
"""


def num(value: float) -> str:
    """A number as a plain PDDL decimal (no exponent), to 12 significant digits."""
    return decimal_text(Decimal(f"{float(value):.12g}"))


def number_term(text: str) -> str:
    """A number written by :func:`num` or :func:`decimal_text` as a PDDL term: a negative
    number as the standard ``(- 15)`` (PDDL's numbers are unsigned; strict parsers refuse
    ``-15``)."""
    return f"(- {text[1:]})" if text.startswith("-") else text


def decimal_text(value: Decimal) -> str:
    """A decimal in plain notation, without trailing zeros (``"0"`` for zero)."""
    text = format(value, "f")
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text
