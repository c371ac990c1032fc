"""The ``shapes:`` section of a YAML problem, and an object's inline shape: boxes, simple
polygons (decomposed into convex pieces) and explicit convex parts, with the vertex caps that
bound the cost of checking a file (``docs/problem-format.md``)."""

from __future__ import annotations

from arrange_up.geometry import shapes as geometry
from arrange_up.io import validation
from arrange_up.io.shape_forms import box_shape, ccw_polygon, centred_shape, convex_decomposition
from arrange_up.io.yaml_source import Node, NodeReader, describe, fmt
from arrange_up.model.problem import (
    ConvexPolygon,
    Point,
    Shape,
)

__all__ = ["MAX_PROBLEM_VERTICES", "SHAPE_EXPECTED", "SHAPE_FORMS", "ShapeReader"]

SHAPE_FORMS = ("box", "polygon", "convex_parts")
SHAPE_EXPECTED = "{box: [w, h]}, {polygon: [...]}, {convex_parts: [...]}"
#: Most polygon vertices (``polygon`` and ``convex_parts`` forms together) a problem may have:
#: ten polygons at the per-polygon cap (``geometry.MAX_POLYGON_VERTICES``). Bounds the time of
#: checking a problem; tabletop problems have a few hundred.
MAX_PROBLEM_VERTICES = 10_000


class ShapeReader(NodeReader):
    """Reads shapes for :class:`~arrange_up.io.yaml_builder.ProblemBuilder`, into its report
    and in its units (set ``units`` before reading)."""

    #: Polygon vertices read so far (``polygon`` and ``convex_parts`` forms), against
    #: :data:`MAX_PROBLEM_VERTICES`.
    vertices = 0

    # -- shapes ---------------------------------------------------------------------------------
    def shapes(self, root: Node) -> dict[str, Shape | None]:
        """Named shapes; a name maps to ``None`` when its shape was invalid (already reported)."""
        shapes: dict[str, Shape | None] = {}
        if not root.has("shapes"):
            return shapes
        node = root.child("shapes")
        if not self.mapping(node, "a mapping from shape names to shapes", null_ok=True):
            return shapes
        if node.is_null:
            return shapes
        for key_node, value_node in node.entries():
            if not isinstance(key_node.value, str):
                self.error(
                    key_node, f"expected a shape name (a string), got {describe(key_node.value)}"
                )
                continue
            shapes[str(key_node.value)] = self.shape_form(value_node, str(key_node.value))
        return shapes

    def shape_form(self, node: Node, name: str | None) -> Shape | None:
        """A shape given as ``{box: ...}``, ``{polygon: ...}`` or ``{convex_parts: ...}``."""
        if not node.is_map:
            self.error(
                node, f"expected a shape: one of {SHAPE_EXPECTED}; got {describe(node.value)}"
            )
            return None
        self.warn_unknown(node, SHAPE_FORMS, "a shape")
        forms = [key for key in SHAPE_FORMS if node.has(key)]
        if not forms:
            self.error(
                node,
                f"a shape needs exactly one of box, polygon or convex_parts; "
                f"expected one of {SHAPE_EXPECTED}",
            )
            return None
        if len(forms) > 1:
            self.error(
                node.key(forms[1]),
                f"a shape has exactly one of box, polygon or convex_parts; found both "
                f"{forms[0]!r} and {forms[1]!r}",
            )
            return None
        form = forms[0]
        child = node.child(form)
        if form == "box":
            return self.box(child, name)
        if form == "polygon":
            return self.polygon(child, name)
        return self.convex_parts(child, name)

    def box(self, node: Node, name: str | None) -> Shape | None:
        size = self.positive(node, self.vector(node, ("width", "height")), "box size")
        if size is None:
            return None
        width, height = (self.units.length_in(v) for v in size)
        if not width * height > 0.0:  # both > 0, but the area rounds to zero (1e-300 x 1e-300)
            self.error(
                node,
                f"the box {fmt(size[0])} x {fmt(size[1])} is degenerate (its area rounds to "
                "zero); expected a box of non-zero area",
            )
            return None
        return box_shape(width, height, name)

    def points(self, node: Node) -> list[Point] | None:
        """A polygon's vertices ``[[x, y], ...]`` (at least three), converted to inches."""
        if not node.is_seq or len(node.value) < 3:
            got = describe(node.value)
            if node.is_seq:
                got = f"{len(node.value)} vertices"
            self.error(
                node, f"expected a polygon [[x, y], ...] with at least 3 vertices, got {got}"
            )
            return None
        # Refused before its vertices are read (one extra entry may be a closing vertex).
        if len(node.value) > geometry.MAX_POLYGON_VERTICES + 1:
            self.too_many_vertices(node, len(node.value))
            return None
        values = [self.vector(item, ("x", "y")) for item in node.items()]
        vectors = [v for v in values if v is not None]
        if len(vectors) < len(values):
            return None
        points = [(self.units.length_in(v[0]), self.units.length_in(v[1])) for v in vectors]
        if len(points) > 3 and points[-1] == points[0]:
            points.pop()  # an explicitly closed outline: the closing vertex repeats the first
        if len(points) > geometry.MAX_POLYGON_VERTICES:
            self.too_many_vertices(node, len(points))
            return None
        self.vertices += len(points)
        if self.vertices > MAX_PROBLEM_VERTICES:
            if self.vertices - len(points) <= MAX_PROBLEM_VERTICES:  # report it once
                self.error(
                    node,
                    f"the polygons so far have {self.vertices} vertices in all; expected at "
                    f"most {MAX_PROBLEM_VERTICES} in a problem (simplify the outlines)",
                )
            return None
        return points

    def too_many_vertices(self, node: Node, count: int) -> None:
        self.error(
            node,
            f"a polygon has {count} vertices; expected at most "
            f"{geometry.MAX_POLYGON_VERTICES} (simplify the outline)",
        )

    def valid_polygon(self, node: Node, points: list[Point], what: str) -> bool:
        try:
            reason = geometry.polygon_problem(tuple(points))
        except Exception as error:  # geometry must not leak a traceback for odd input
            reason = f"cannot be analysed ({error})"
        if reason:
            self.error(
                node,
                f"{what} {reason}; expected a simple polygon (vertices in order around its "
                "boundary, no self-intersections, non-zero area)",
            )
            return False
        return True

    def polygon(self, node: Node, name: str | None) -> Shape | None:
        points = self.points(node)
        if points is None or not self.valid_polygon(node, points, "the polygon"):
            return None
        try:
            parts = convex_decomposition(points)
        except Exception as error:
            self.error(node, f"the polygon could not be decomposed into convex parts ({error})")
            return None
        return centred_shape(parts, name)

    def convex_parts(self, node: Node, name: str | None) -> Shape | None:
        items = self.list_of(node, "a non-empty list of convex polygons [[[x, y], ...], ...]")
        if items is None:
            return None
        parts: list[tuple[int, Node, ConvexPolygon]] = []
        ok = True
        for index, item in enumerate(items):
            points = self.points(item)
            if points is None or not self.valid_polygon(item, points, f"part [{index}]"):
                ok = False
                continue
            if not geometry.is_convex(tuple(points)):
                self.error(
                    item,
                    f"part [{index}] is not convex; expected convex polygons (use 'polygon:' "
                    "to have a non-convex shape decomposed for you)",
                )
                ok = False
                continue
            parts.append((index, item, ccw_polygon(points)))
        area_unit = self.units.length_factor**2
        limit = validation.MAX_LISTED_OVERLAPS
        found = validation.part_overlaps([p for _, _, p in parts], max_overlaps=limit + 1)
        for count, (i, j, overlap) in enumerate(found, start=1):
            (index_i, _, _), (index_j, node_j, _) = parts[i], parts[j]
            ok = False
            if count > limit:
                self.error(
                    node_j,
                    f"part [{index_j}] and more parts overlap: only the first {limit} "
                    "overlapping pairs are listed, the others are not looked for; the convex "
                    "parts of a shape may touch but not overlap",
                )
                break
            self.error(
                node_j,
                f"parts [{index_i}] and [{index_j}] overlap (area "
                f"{fmt(overlap / area_unit)} {self.units.length}²); the convex parts of "
                "a shape may touch but not overlap",
            )
        if not ok:
            return None
        return centred_shape(tuple(p for _, _, p in parts), name)
