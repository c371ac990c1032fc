"""The shape catalogue: object types of PDDL problems, with their kind and geometry.

PDDL cannot describe geometry, so a ``.pddl`` problem types each object by a *shape type*
(``block-1x1``, ``paddle-short``, ``tee``, ...) and ``semantics/shapes.yaml`` says what each
type is: a kind (part, manipulator, fixture, obstacle) and a shape in one of the problem
format's forms (``box``, ``polygon``, ``convex_parts``; inches). See that file's header.

Shapes are built by :mod:`arrange_up.io.shape_forms`, as the YAML reader builds them from a
``.yaml`` file, so a problem whose objects use catalogue shapes is the same
:class:`~arrange_up.model.problem.ArrangementProblem` whichever format it was read from. A box
type gives an unnamed shape (like an inline ``{box: [w, h]}``); a polygon type gives a shape
named after the type (like a shape declared under ``shapes:`` with that name).

This module never imports unified-planning.

    >>> from arrange_up.io.shape_catalogue import load_catalogue
    >>> entry = load_catalogue().entry("block-1x1")
    >>> entry.kind.value, entry.shape.box
    ('part', (1.0, 1.0))
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

from ruamel.yaml import YAML
from ruamel.yaml.error import YAMLError
from shapely.geometry import Polygon
from shapely.ops import unary_union

from arrange_up.counts import is_number
from arrange_up.geometry import shapes as geometry
from arrange_up.io.resources import shipped_dir
from arrange_up.io.shape_forms import box_shape, ccw_polygon, centred_shape, convex_decomposition
from arrange_up.model.problem import ObjectKind, Shape

__all__ = [
    "CATALOGUE_FORMAT",
    "Catalogue",
    "CatalogueEntry",
    "CatalogueError",
    "catalogue_path",
    "load_catalogue",
    "semantics_dir",
]

CATALOGUE_FORMAT = "arrange-up-shapes/1"
#: Valid PDDL names (PDDL 2.1: a letter, then letters, digits, ``-`` and ``_``).
PDDL_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_-]*")
#: Two shapes are the same when their outlines differ by less than this area (square inches).
SAME_SHAPE_AREA = 1e-9


class CatalogueError(ValueError):
    """The shape catalogue file is unreadable or malformed; the message names file and entry."""


@dataclass(frozen=True)
class CatalogueEntry:
    """One shape type: its PDDL type name, kind and shape (inches, centroid at the origin)."""

    type_name: str
    kind: ObjectKind
    shape: Shape
    description: str = ""


@dataclass(frozen=True)
class Catalogue:
    """Every shape type of a catalogue file, in file order."""

    entries: tuple[CatalogueEntry, ...]
    path: str

    @property
    def type_names(self) -> tuple[str, ...]:
        return tuple(e.type_name for e in self.entries)

    def entry(self, type_name: str) -> CatalogueEntry | None:
        """The entry of ``type_name`` (case-insensitive, as PDDL names are), or ``None``."""
        key = type_name.lower()
        for e in self.entries:
            if e.type_name.lower() == key:
                return e
        return None

    def match(self, kind: ObjectKind, shape: Shape) -> CatalogueEntry | None:
        """The entry of this kind whose geometry equals ``shape``, or ``None``.

        Geometry is compared as outlines (symmetric difference below :data:`SAME_SHAPE_AREA`),
        not vertex by vertex, so a shape written from another starting vertex still matches.
        """
        for e in self.entries:
            if e.kind is kind and same_geometry(e.shape, shape):
                return e
        return None

    def of_kind(self, kind: ObjectKind) -> tuple[CatalogueEntry, ...]:
        return tuple(e for e in self.entries if e.kind is kind)


def semantics_dir() -> Path:
    """The folder of the shipped semantics: an installed wheel's
    ``arrange_up/_shipped/semantics`` or the checkout's ``semantics/``."""
    return shipped_dir("semantics", "semantics")


def catalogue_path() -> Path:
    """The shipped catalogue file, ``semantics/shapes.yaml``."""
    return semantics_dir() / "shapes.yaml"


def load_catalogue(path: str | Path | None = None) -> Catalogue:
    """Read a shape catalogue (default: the shipped one). Cached per path.

    Raises :class:`CatalogueError` naming the file and the entry for a malformed catalogue.
    """
    return _load(str(Path(path) if path is not None else catalogue_path()))


def same_geometry(a: Shape, b: Shape) -> bool:
    """True if the two shapes cover the same region of their own frames."""
    if a.parts == b.parts:
        return True
    outline_a = unary_union([Polygon(p) for p in a.parts])
    outline_b = unary_union([Polygon(p) for p in b.parts])
    return bool(outline_a.symmetric_difference(outline_b).area <= SAME_SHAPE_AREA)


# ---------------------------------------------------------------------------------------------
# reading
# ---------------------------------------------------------------------------------------------
@cache
def _load(path: str) -> Catalogue:
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as error:
        raise CatalogueError(f"{path}: cannot read the shape catalogue: {error}") from None
    try:
        data: Any = YAML(typ="safe", pure=True).load(text)
    except YAMLError as error:
        raise CatalogueError(f"{path}: not valid YAML: {error}") from None
    if not isinstance(data, dict) or data.get("format") != CATALOGUE_FORMAT:
        raise CatalogueError(
            f"{path}: expected a mapping with 'format: {CATALOGUE_FORMAT}' and 'types'"
        )
    types = data.get("types")
    if not isinstance(types, dict) or not types:
        raise CatalogueError(f"{path}: types: expected a non-empty mapping of shape types")
    entries = []
    seen: set[str] = set()
    for name, spec in types.items():
        where = f"{path}: types.{name}"
        if not isinstance(name, str) or not PDDL_NAME.fullmatch(name):
            raise CatalogueError(
                f"{where}: expected a PDDL name (a letter, then letters, digits, '-' or '_')"
            )
        if name.lower() in seen:
            raise CatalogueError(f"{where}: duplicate type (PDDL names are case-insensitive)")
        seen.add(name.lower())
        entries.append(_entry(name, spec, where))
    return Catalogue(tuple(entries), path)


def _entry(name: str, spec: Any, where: str) -> CatalogueEntry:
    if not isinstance(spec, dict):
        raise CatalogueError(
            f"{where}: expected a mapping {{kind: ..., box|polygon|convex_parts:"
            " ..., description: ...}}"
        )
    kinds = [k.value for k in ObjectKind]
    if spec.get("kind") not in kinds:
        raise CatalogueError(
            f"{where}.kind: expected one of {', '.join(kinds)}, got {spec.get('kind')!r}"
        )
    forms = [f for f in ("box", "polygon", "convex_parts") if f in spec]
    if len(forms) != 1:
        raise CatalogueError(f"{where}: expected exactly one of box, polygon, convex_parts")
    try:
        shape = build_shape(forms[0], spec[forms[0]], name)
    except (TypeError, ValueError) as error:
        raise CatalogueError(f"{where}.{forms[0]}: {error}") from None
    description = spec.get("description", "")
    return CatalogueEntry(name, ObjectKind(spec["kind"]), shape, str(description or ""))


def build_shape(form: str, value: Any, name: str) -> Shape:
    """Build a :class:`Shape` from one shape form, exactly as the YAML loader does.

    ``form`` is ``"box"`` (``value = [w, h]``; unnamed shape), ``"polygon"`` or
    ``"convex_parts"`` (shape named ``name``). Raises ``ValueError`` for invalid geometry.
    """
    if form == "box":
        width, height = (float(v) for v in _numbers(value, 2))
        return box_shape(width, height)
    if form == "polygon":
        points = _points(value)
        reason = geometry.polygon_problem(points)
        if reason:
            raise ValueError(f"the polygon {reason}")
        return centred_shape(convex_decomposition(points), name)
    if form == "convex_parts":
        if not isinstance(value, list) or not value:
            raise ValueError("expected a non-empty list of convex polygons")
        pieces = []
        for index, item in enumerate(value):
            points = _points(item)
            if geometry.polygon_problem(points) or not geometry.is_convex(points):
                raise ValueError(f"part [{index}] is not a valid convex polygon")
            pieces.append(ccw_polygon(points))
        return centred_shape(tuple(pieces), name)
    raise ValueError(f"unknown shape form {form!r}")


def _numbers(value: Any, n: int) -> list[float]:
    if not isinstance(value, list) or len(value) != n or not all(is_number(v) for v in value):
        raise ValueError(f"expected a list of {n} numbers, got {value!r}")
    return [float(v) for v in value]


def _points(value: Any) -> tuple[tuple[float, float], ...]:
    if not isinstance(value, list) or len(value) < 3:
        raise ValueError("expected a polygon [[x, y], ...] with at least 3 vertices")
    return tuple(tuple(_numbers(p, 2)) for p in value)  # type: ignore[misc]
