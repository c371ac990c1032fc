"""The YAML problem builder: a parsed ``.yaml`` file to an :class:`ArrangementProblem`.

:class:`ProblemBuilder` has one method per section of the format (``docs/problem-format.md``;
the rules are summarised in :mod:`arrange_up.io.yaml_problem`), each recording every problem it
finds in the report and returning ``None`` for what is invalid; :meth:`ProblemBuilder.build`
returns a problem only when the whole file is valid.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

from arrange_up.geometry import shapes as geometry
from arrange_up.io import validation
from arrange_up.io.shape_forms import box_shape, ccw_polygon, centred_shape, convex_decomposition
from arrange_up.io.validation import Placed
from arrange_up.io.yaml_source import Node, NodeReader, at, describe, fmt, is_number, suggest
from arrange_up.model.problem import (
    DEFAULT_CONTROLLER,
    WALL_EDGES,
    ArrangementProblem,
    Controller,
    ControllerKind,
    ConvexPolygon,
    Goal,
    InitialObject,
    ObjectKind,
    ObjectSpec,
    PlanningHints,
    Point,
    Pose,
    Shape,
    Table,
    Uncertainty,
)
from arrange_up.model.units import ANGLE_UNITS, LENGTH_UNITS, Units

__all__ = [
    "DEFAULT_GOAL_TOLERANCE_IN",
    "FORMAT_VERSION",
    "MAX_PROBLEM_VERTICES",
    "SUPPORTED_FORMATS",
    "ProblemBuilder",
]

FORMAT_VERSION = "arrange-up/1"
#: The ``format:`` values this loader reads.
SUPPORTED_FORMATS: tuple[str, ...] = (FORMAT_VERSION,)
#: Goal tolerance in x and y (inches, whatever the file's units) when ``goal.tolerance`` is
#: omitted; the angle is then unconstrained.
DEFAULT_GOAL_TOLERANCE_IN = 0.2

NAME_PATTERN = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*")
TOP_LEVEL_KEYS = (
    "format",
    "name",
    "description",
    "units",
    "table",
    "shapes",
    "objects",
    "initial",
    "goal",
    "uncertainty",
    "planning",
    "controller",
)
SHAPE_FORMS = ("box", "polygon", "convex_parts")
SHAPE_EXPECTED = "{box: [w, h]}, {polygon: [...]}, {convex_parts: [...]}"
PUSH_DIRECTIONS = ("+x", "-x", "+y", "-y")
PLANNING_KEYS = ("place_offsets", "place_angles", "push_distances", "push_directions", "max_nodes")
CONTROLLER_KEYS = ("kind", "kp", "kp_angle", "speed", "force", "torque")
#: Keys the servo controller reads (the others tune the compliant controller only).
SERVO_KEYS = ("kind", "speed", "force")
UNCERTAINTY_KEYS = ("place", "push", "friction", "part_density", "manipulator_density")
KIND_NAMES = tuple(kind.value for kind in ObjectKind)
_ARTICLE = {"part": "a part", "manipulator": "a manipulator", "fixture": "a fixture"}
_ARTICLE["obstacle"] = "an obstacle"
#: Most polygon vertices (``polygon`` and ``convex_parts`` forms together) a problem may have:
#: ten polygons at the per-polygon cap (``geometry.MAX_POLYGON_VERTICES``). Bounds the time of
#: checking a problem; tabletop problems have a few hundred.
MAX_PROBLEM_VERTICES = 10_000


@dataclass
class _Object:
    """An object as far as it could be read (``None`` fields were invalid and reported)."""

    name: str
    node: Node
    kind: ObjectKind | None = None
    shape: Shape | None = None
    pose: Pose | None = None
    pose_node: Node | None = None
    ok: bool = True


class ProblemBuilder(NodeReader):
    """Builds the problem of one parsed file, section by section (see the module docstring)."""

    #: Polygon vertices read so far (``polygon`` and ``convex_parts`` forms), against
    #: :data:`MAX_PROBLEM_VERTICES`.
    vertices = 0

    # -- the whole file ----------------------------------------------------------------------
    def build(self, root: Node) -> ArrangementProblem | None:
        """The problem of the top-level mapping ``root``, or ``None`` if anything is invalid."""
        self.warn_unknown(root, TOP_LEVEL_KEYS, "the problem")

        self.format(root)
        name = self.name(root)
        description = self.description(root)
        if root.has("units"):
            self.units = self.read_units(root.child("units"))
        table = self.table(root)
        shapes = self.shapes(root)
        objects = self.objects(root, shapes)
        initial = self.initial(root, objects)
        self.check_placement(table, objects, initial)
        goal = self.goal(root, objects)
        uncertainty = self.uncertainty(root)
        planning = self.planning(root)
        controller = self.controller(root)

        if table is not None and goal is not None:
            self.check_goal_on_table(root, table, objects, goal)

        if self.report.error_count:
            return None
        assert name is not None and table is not None and goal is not None
        assert uncertainty is not None and planning is not None and controller is not None
        specs = tuple(
            ObjectSpec(o.name, o.kind, o.shape, o.pose)  # type: ignore[arg-type]
            for o in objects.values()
        )
        problem = ArrangementProblem(
            name=name,
            table=table,
            objects=specs,
            initial=tuple(entry for entry, _ in initial),
            goal=goal,
            uncertainty=uncertainty,
            planning=planning,
            controller=controller,
            description=description or "",
            units=self.units,
            source=self.report.source,
        )
        if validation.unsampleable(problem):
            self.error(
                root.child("initial"),
                f"no collision-free initial state in {validation.SAMPLE_DRAWS} draws from the "
                "initial uncertainties (objects overlap each other, an obstacle or a wall in "
                "every one); expected uncertainties from which particles can be drawn",
            )
            return None
        return problem

    def check_goal_on_table(
        self, root: Node, table: Table, objects: dict[str, _Object], goal: Goal
    ) -> None:
        """An absolute goal whose part cannot be on the table is an error; one whose part
        sticks out of the table at the target pose a warning."""
        if goal.is_relative:
            return
        poses = root.child("goal").child("poses")
        nodes = {str(key.value): value for key, value in poses.entries()}
        units = self.units
        for name, pose in goal.targets:
            shape = objects[name].shape
            if shape is None:
                continue
            found = validation.goal_outside(shape, pose, goal.tolerance[:2], table.size)
            if found is None:
                continue
            verdict, (xmin, ymin, xmax, ymax) = found
            spans = ", ".join(
                f"{axis} {fmt(units.length_out(lo))}..{fmt(units.length_out(hi))}"
                for axis, lo, hi in (("x", xmin, xmax), ("y", ymin, ymax))
            )
            width, depth = (fmt(units.length_out(v)) for v in table.size)
            where = f"the table [0, {width}] x [0, {depth}] {units.length}"
            if verdict == "unreachable":
                self.error(
                    nodes[name],
                    f"the goal of {name} is off the table even within the tolerance (its "
                    f"centroid must be on {where}); expected a goal pose on the table",
                )
            else:
                self.report.warning(
                    nodes[name],
                    None,
                    f"at its goal pose {name} spans {spans}, beyond {where}: only poses "
                    "within the tolerance that keep it on the table can meet the goal",
                )

    # -- format, name, description, units -------------------------------------------------------
    def format(self, root: Node) -> None:
        if not root.has("format"):
            return
        node = root.child("format")
        if node.value not in SUPPORTED_FORMATS:
            shown = repr(node.value) if isinstance(node.value, str) else describe(node.value)
            self.error(
                node,
                f"unsupported format {shown}; this loader reads {', '.join(SUPPORTED_FORMATS)}",
            )

    def name(self, root: Node) -> str | None:
        node = self.required(root, "name", "the problem's name (a string)")
        if node is None:
            return None
        return self.string(node, "the problem's name (a non-empty string)")

    def description(self, root: Node) -> str | None:
        if not root.has("description") or root.child("description").is_null:
            return ""
        node = root.child("description")
        if isinstance(node.value, str):
            return str(node.value)
        self.error(node, f"expected a string, got {describe(node.value)}")
        return None

    def read_units(self, node: Node) -> Units:
        if not self.mapping(node, "a mapping like {length: cm, angle: rad}", null_ok=True):
            return Units()
        if node.is_null:
            return Units()
        self.warn_unknown(node, ("length", "angle"), "'units'")
        length, angle = "in", "deg"
        for key, table, default in (("length", LENGTH_UNITS, "in"), ("angle", ANGLE_UNITS, "deg")):
            if not node.has(key):
                continue
            child = node.child(key)
            if isinstance(child.value, str) and child.value in table:
                if key == "length":
                    length = str(child.value)
                else:
                    angle = str(child.value)
            else:
                shown = repr(child.value) if isinstance(child.value, str) else describe(child.value)
                self.error(
                    child,
                    f"unknown {key} unit {shown}; expected one of {' | '.join(table)} "
                    f"(default {default})",
                )
        return Units(length, angle)

    # -- table ----------------------------------------------------------------------------------
    def table(self, root: Node) -> Table | None:
        node = self.required(root, "table", "{size: [width, depth], walls: [...]}")
        if node is None:
            return None
        if not self.mapping(node, "a mapping {size: [width, depth], walls: [...]}"):
            return None
        self.warn_unknown(node, ("size", "walls"), "'table'")
        size = None
        if node.has("size"):
            size_node = node.child("size")
            size = self.positive(size_node, self.vector(size_node, ("width", "depth")), "size")
        else:
            self.error(node.missing("size"), "missing required key; expected [width, depth]")
        walls: tuple[str, ...] | None = WALL_EDGES
        if node.has("walls"):
            walls = self.walls(node.child("walls"))
        if size is None or walls is None:
            return None
        lf = self.units.length_factor
        return Table((size[0] * lf, size[1] * lf), walls)

    def walls(self, node: Node) -> tuple[str, ...] | None:
        expected = f"a list of edges drawn from {', '.join(WALL_EDGES)} ([] for none)"
        if not node.is_seq:
            self.error(node, f"expected {expected}, got {describe(node.value)}")
            return None
        chosen: dict[str, Node] = {}
        ok = True
        for item in node.items():
            if item.value not in WALL_EDGES:
                self.error(
                    item,
                    f"unknown wall {describe(item.value)}; expected one of {', '.join(WALL_EDGES)}",
                )
                ok = False
            elif item.value in chosen:
                self.error(
                    item,
                    f"wall {item.value!r} is listed twice (first at {at(chosen[item.value])}); "
                    "list each edge at most once",
                )
                ok = False
            else:
                chosen[str(item.value)] = item
        return tuple(e for e in WALL_EDGES if e in chosen) if ok else None

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
            return self.too_many_vertices(node, len(node.value))
        values = [self.vector(item, ("x", "y")) for item in node.items()]
        if any(v is None for v in values):
            return None
        points = [(self.units.length_in(v[0]), self.units.length_in(v[1])) for v in values]  # type: ignore[index]
        if len(points) > 3 and points[-1] == points[0]:
            points.pop()  # an explicitly closed outline: the closing vertex repeats the first
        if len(points) > geometry.MAX_POLYGON_VERTICES:
            return self.too_many_vertices(node, len(points))
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
        for i, j, overlap in validation.part_overlaps([p for _, _, p in parts]):
            (index_i, _, _), (index_j, node_j, _) = parts[i], parts[j]
            self.error(
                node_j,
                f"parts [{index_i}] and [{index_j}] overlap (area "
                f"{fmt(overlap / area_unit)} {self.units.length}²); the convex parts of "
                "a shape may touch but not overlap",
            )
            ok = False
        if not ok:
            return None
        return centred_shape(tuple(p for _, _, p in parts), name)

    # -- objects --------------------------------------------------------------------------------
    def objects(self, root: Node, shapes: dict[str, Shape | None]) -> dict[str, _Object]:
        objects: dict[str, _Object] = {}
        node = self.required(
            root, "objects", "a mapping from object names to {kind: ..., shape: ...}"
        )
        if node is None:
            return objects
        if not node.is_map or not node.value:
            got = "an empty mapping" if node.is_map else describe(node.value)
            self.error(
                node,
                f"expected a mapping from object names to {{kind: ..., shape: ...}}, got {got}",
            )
            return objects
        for key_node, value_node in node.entries():
            name = key_node.value
            if not isinstance(name, str) or not NAME_PATTERN.fullmatch(name):
                shown = repr(name) if isinstance(name, str) else describe(name)
                self.error(
                    key_node,
                    f"invalid object name {shown}; expected an identifier: letters, digits, "
                    "'_' and '-', starting with a letter or '_'",
                )
                if not isinstance(name, str):
                    continue
                obj = _Object(str(name), value_node, ok=False)
            else:
                obj = _Object(str(name), value_node)
            objects[obj.name] = obj
            self.object(obj, value_node, shapes)
        return objects

    def object(self, obj: _Object, node: Node, shapes: dict[str, Shape | None]) -> None:
        if not self.mapping(node, "a mapping {kind: ..., shape: ...}"):
            obj.ok = False
            return
        self.warn_unknown(node, ("kind", "shape", "pose"), "an object")
        if node.has("kind"):
            kind_node = node.child("kind")
            if kind_node.value in KIND_NAMES:
                obj.kind = ObjectKind(kind_node.value)
            else:
                shown = (
                    repr(kind_node.value)
                    if isinstance(kind_node.value, str)
                    else describe(kind_node.value)
                )
                self.error(
                    kind_node,
                    f"unknown object kind {shown}; expected one of {', '.join(KIND_NAMES)}",
                )
        else:
            self.error(
                node.missing("kind"),
                f"missing required key; expected one of {', '.join(KIND_NAMES)}",
            )
        if node.has("shape"):
            obj.shape = self.object_shape(node.child("shape"), shapes)
        else:
            self.error(
                node.missing("shape"),
                f"missing required key; expected the name of a "
                f"shape declared under 'shapes' or an inline {SHAPE_EXPECTED}",
            )
        if obj.kind is ObjectKind.OBSTACLE:
            if node.has("pose"):
                obj.pose_node = node.child("pose")
                obj.pose = self.pose(obj.pose_node)
            else:
                self.error(
                    node.missing("pose"),
                    "missing required key; an obstacle never moves "
                    "and needs its pose [x, y, theta] here",
                )
        elif obj.kind is not None and node.has("pose"):
            self.error(
                node.key("pose"),
                f"only obstacles have a pose under 'objects'; {obj.name} is "
                f"{_ARTICLE[obj.kind.value]}: give its starting pose under 'initial' (or leave "
                "it out to start it off the table)",
            )
        if obj.kind is None or obj.shape is None:
            obj.ok = False
        if obj.kind is ObjectKind.OBSTACLE and obj.pose is None:
            obj.ok = False

    def object_shape(self, node: Node, shapes: dict[str, Shape | None]) -> Shape | None:
        if isinstance(node.value, str):
            name = str(node.value)
            if name in shapes:
                return shapes[name]  # None if invalid: reported where it is declared
            declared = ", ".join(shapes)
            choices = (
                f"one of the shapes declared under 'shapes' ({declared}) or an inline "
                if shapes
                else "an inline "
            )
            extra = "" if shapes else " (no shapes are declared under 'shapes')"
            self.error(node, f"unknown shape {name!r}; expected {choices}{SHAPE_EXPECTED}{extra}")
            return None
        if node.is_map:
            return self.shape_form(node, None)
        self.error(
            node,
            f"expected the name of a shape declared under 'shapes' or an inline "
            f"{SHAPE_EXPECTED}; got {describe(node.value)}",
        )
        return None

    def declared(self, key_node: Node, objects: dict[str, _Object], where: str) -> _Object | None:
        """The object a key names, or ``None`` after reporting an undeclared name."""
        name = key_node.value
        if isinstance(name, str) and name in objects:
            return objects[name]
        shown = repr(name) if isinstance(name, str) else describe(name)
        declared = ", ".join(objects) or "none"
        self.error(
            key_node,
            f"{shown} in {where} is not declared under 'objects'; "
            f"expected one of the declared objects ({declared})",
        )
        return None

    # -- initial --------------------------------------------------------------------------------
    def initial(self, root: Node, objects: dict[str, _Object]) -> list[tuple[InitialObject, Node]]:
        """The valid initial entries (invalid ones are reported and left out)."""
        entries: list[tuple[InitialObject, Node]] = []
        if not root.has("initial"):
            return entries
        node = root.child("initial")
        expected = "a mapping from object names to {pose: [x, y, theta]}"
        if not self.mapping(node, expected, null_ok=True) or node.is_null:
            return entries
        for key_node, value_node in node.entries():
            obj = self.declared(key_node, objects, "'initial'")
            if obj is not None and obj.kind is ObjectKind.OBSTACLE:
                self.error(
                    key_node,
                    f"{obj.name} is an obstacle, which is fixed at the pose given under "
                    "'objects'; expected only parts, manipulators and fixtures in 'initial'",
                )
                obj = None
            entry = self.initial_entry(value_node, str(key_node.value))
            if obj is not None and entry is not None:
                entries.append((entry, value_node))
        return entries

    def initial_entry(self, node: Node, name: str) -> InitialObject | None:
        if not self.mapping(node, "a mapping {pose: [x, y, theta], uncertainty: [dx, dy, dtheta]}"):
            return None
        self.warn_unknown(node, ("pose", "uncertainty"), "an initial entry")
        pose = None
        if node.has("pose"):
            pose = self.pose(node.child("pose"))
        else:
            self.error(node.missing("pose"), "missing required key; expected [x, y, theta]")
        uncertainty: tuple[float, float, float] | None = (0.0, 0.0, 0.0)
        if node.has("uncertainty"):
            uncertainty = self.half_widths(node.child("uncertainty"))
        if pose is None:
            return None
        # An invalid uncertainty is already reported; the pose still takes part in the
        # placement checks so that all problems are found in one pass.
        return InitialObject(name, pose, uncertainty or (0.0, 0.0, 0.0))

    def check_placement(
        self,
        table: Table | None,
        objects: dict[str, _Object],
        initial: list[tuple[InitialObject, Node]],
    ) -> None:
        """Nominal footprints of initial objects and obstacles: on the table, not overlapping.

        Objects whose shape, kind or pose is invalid are skipped (already reported).
        """
        placed: list[tuple[Placed, Node]] = []
        for obj in objects.values():
            if obj.ok and obj.kind is ObjectKind.OBSTACLE:
                assert obj.shape is not None and obj.pose is not None and obj.pose_node
                placed.append((Placed(obj.name, obj.shape, obj.pose), obj.pose_node))
        for entry, node in initial:
            obj = objects[entry.name]
            if obj.ok and obj.shape is not None:
                placed.append((Placed(entry.name, obj.shape, entry.pose), node.child("pose")))
        placed.sort(key=lambda p: (p[1].line or 0, p[1].column or 0))
        table_size = None if table is None else table.size
        checks = validation.check_placement([item for item, _ in placed], table_size)

        units = self.units
        if table is not None:
            width, depth = table.size
            for (item, node), check in zip(placed, checks, strict=True):
                if check.outside is not None:
                    xmin, ymin, xmax, ymax = check.outside
                    spans = ", ".join(
                        f"{axis} {fmt(units.length_out(lo))}..{fmt(units.length_out(hi))}"
                        for axis, lo, hi in (("x", xmin, xmax), ("y", ymin, ymax))
                    )
                    self.error(
                        node,
                        f"{item.name} lies outside the table: at this nominal pose its shape "
                        f"spans {spans}; expected it within the table [0, "
                        f"{fmt(units.length_out(width))}] x [0, "
                        f"{fmt(units.length_out(depth))}] {units.length}",
                    )
        area_unit = units.length_factor**2
        for (later, node), check in zip(placed, checks, strict=True):
            for index, overlap in check.overlaps:
                earlier, earlier_node = placed[index]
                self.error(
                    node,
                    f"{later.name} overlaps {earlier.name} ({earlier_node.path}, line "
                    f"{earlier_node.line}) at their nominal poses (overlap area "
                    f"{fmt(overlap / area_unit)} {units.length}²); expected shapes that "
                    "touch at most",
                )

    # -- goal -----------------------------------------------------------------------------------
    def goal(self, root: Node, objects: dict[str, _Object]) -> Goal | None:
        node = self.required(
            root,
            "goal",
            "a mapping with exactly one of 'poses' or 'relative', and a 'tolerance'",
        )
        if node is None:
            return None
        if not self.mapping(
            node, "a mapping with 'tolerance' and exactly one of 'poses' or 'relative'"
        ):
            return None
        self.warn_unknown(node, ("tolerance", "poses", "relative"), "'goal'")

        tolerance: tuple[float, float, float | None] | None
        if node.has("tolerance"):
            tolerance = self.tolerance(node.child("tolerance"))
        else:
            tolerance = (DEFAULT_GOAL_TOLERANCE_IN, DEFAULT_GOAL_TOLERANCE_IN, None)
            self.report.warning(
                node.missing("tolerance"),
                None,
                f"no tolerance given; using the default [{DEFAULT_GOAL_TOLERANCE_IN}, "
                f"{DEFAULT_GOAL_TOLERANCE_IN}] inches with any angle",
            )

        has_poses, has_relative = node.has("poses"), node.has("relative")
        if has_poses and has_relative:
            self.error(
                node.key("relative"),
                "a goal has exactly one of 'poses' (absolute) or 'relative'; found both",
            )
            return None
        if not has_poses and not has_relative:
            self.error(
                node.missing("poses"),
                "missing; expected exactly one of 'poses' "
                "(absolute goal) or 'relative' (goal relative to a reference part)",
            )
            return None

        reference: str | None = None
        if has_relative:
            relative = node.child("relative")
            if not self.mapping(relative, "a mapping {reference: PART, poses: {...}}"):
                return None
            self.warn_unknown(relative, ("reference", "poses"), "'goal.relative'")
            reference = self.reference(relative, objects)
            if not relative.has("poses"):
                self.error(
                    relative.missing("poses"),
                    "missing required key; expected a mapping "
                    "from part names to poses [x, y, theta] in the reference's frame",
                )
                return None
            targets = self.targets(relative.child("poses"), objects, reference)
            if reference is None:
                return None
        else:
            targets = self.targets(node.child("poses"), objects, None)
        if targets is None or tolerance is None:
            return None
        return Goal(targets, tolerance, reference)

    def tolerance(self, node: Node) -> tuple[float, float, float | None] | None:
        values = self.vector(node, ("dx", "dy"), ("dx", "dy", "dtheta"))
        values = self.non_negative(node, values, "tolerance")
        if values is None:
            return None
        dx, dy = self.units.length_in(values[0]), self.units.length_in(values[1])
        if len(values) == 2:
            return (dx, dy, None)
        dtheta = self.angle(node.items()[2], values[2])
        return None if dtheta is None else (dx, dy, dtheta)

    def reference(self, relative: Node, objects: dict[str, _Object]) -> str | None:
        node = self.required(relative, "reference", "the name of a declared part")
        if node is None:
            return None
        if not isinstance(node.value, str):
            self.error(node, f"expected the name of a declared part, got {describe(node.value)}")
            return None
        obj = self.declared(node, objects, "'goal.relative.reference'")
        if obj is None:
            return None
        if obj.kind is None:
            return None
        if obj.kind is not ObjectKind.PART:
            self.error(
                node,
                f"the reference of a relative goal must be a part; {obj.name} is "
                f"{_ARTICLE[obj.kind.value]}",
            )
            return None
        return obj.name

    def targets(
        self, node: Node, objects: dict[str, _Object], reference: str | None
    ) -> tuple[tuple[str, Pose], ...] | None:
        if not node.is_map or not node.value:
            got = "an empty mapping" if node.is_map else describe(node.value)
            self.error(
                node, f"expected a mapping from part names to poses [x, y, theta], got {got}"
            )
            return None
        targets: list[tuple[str, Pose]] = []
        ok = True
        where = "'goal.relative.poses'" if node.path.endswith("relative.poses") else "the goal"
        for key_node, value_node in node.entries():
            obj = self.declared(key_node, objects, where)
            if obj is not None and obj.kind is not None and obj.kind is not ObjectKind.PART:
                self.error(
                    key_node,
                    f"a goal for a non-part: {obj.name} is {_ARTICLE[obj.kind.value]}; only "
                    "parts have goal poses",
                )
                obj = None
            elif obj is not None and obj.name == reference:
                self.error(
                    key_node,
                    f"{obj.name} is the reference of this relative goal and cannot have a pose "
                    "relative to itself; expected only the other parts here",
                )
                obj = None
            pose = self.pose(value_node)
            if obj is None or pose is None or obj.kind is None:
                ok = False
                continue
            targets.append((obj.name, pose))
        return tuple(targets) if ok else None

    # -- uncertainty ----------------------------------------------------------------------------
    def uncertainty(self, root: Node) -> Uncertainty | None:
        default = Uncertainty()
        if not root.has("uncertainty"):
            return default
        node = root.child("uncertainty")
        if not self.mapping(
            node, "a mapping with any of " + ", ".join(UNCERTAINTY_KEYS), null_ok=True
        ):
            return None
        if node.is_null:
            return default
        self.warn_unknown(node, UNCERTAINTY_KEYS, "'uncertainty'")
        values: dict[str, Any] = {}
        ok = True
        for key in ("place", "push"):
            if node.has(key):
                values[key] = self.half_widths(node.child(key))
                ok &= values[key] is not None
        units = self.units
        # densities must be positive: a body of zero mass cannot be simulated
        for key, convert, positive in (
            ("friction", float, False),
            ("part_density", units.density_in, True),
            ("manipulator_density", units.density_in, True),
        ):
            if node.has(key):
                values[key] = self.range(node.child(key), convert, positive=positive)
                ok &= values[key] is not None
        friction = values.get("friction")
        if friction is not None and friction[1] > validation.MAX_FRICTION:
            self.report.warning(
                node.child("friction"),
                None,
                f"friction up to {fmt(friction[1])} is far above real table-top materials "
                f"(below ~1.5); every push will stick. Expected at most "
                f"{fmt(validation.MAX_FRICTION)}: check the value",
            )
        return Uncertainty(**values) if ok else None

    # -- planning hints -------------------------------------------------------------------------
    def planning(self, root: Node) -> PlanningHints | None:
        if not root.has("planning"):
            return PlanningHints()
        node = root.child("planning")
        if not self.mapping(
            node, "a mapping of planning hints (" + ", ".join(PLANNING_KEYS) + ")", null_ok=True
        ):
            return None
        if node.is_null:
            return PlanningHints()
        ok = True
        for key_node, _ in node.entries():
            if key_node.value not in PLANNING_KEYS:
                self.error(
                    key_node,
                    f"unknown planning hint {key_node.value!r}"
                    f"{suggest(key_node.value, PLANNING_KEYS)}; expected one of "
                    f"{', '.join(PLANNING_KEYS)} (a misspelt hint would silently change "
                    "planning)",
                )
                ok = False
        hints: dict[str, Any] = {}
        units = self.units
        if node.has("place_offsets"):
            items = self.list_of(node.child("place_offsets"), "a non-empty list of [dx, dy]")
            offsets = None if items is None else [self.vector(i, ("dx", "dy")) for i in items]
            if offsets is None or any(o is None for o in offsets):
                ok = False
            else:
                hints["place_offsets"] = tuple(
                    (units.length_in(o[0]), units.length_in(o[1]))  # type: ignore[index]
                    for o in offsets
                )
        if node.has("place_angles"):
            child = node.child("place_angles")
            numbers = self.numbers(child, "angle", positive=False)
            angles = None
            if numbers is not None:
                angles = [self.angle(i, v) for i, v in zip(child.items(), numbers, strict=True)]
            ok &= angles is not None and None not in angles
            if ok and angles is not None:
                hints["place_angles"] = tuple(angles)
        if node.has("push_distances"):
            numbers = self.numbers(node.child("push_distances"), "distance", positive=True)
            ok &= numbers is not None
            if numbers is not None:
                hints["push_distances"] = tuple(units.length_in(v) for v in numbers)
        if node.has("push_directions"):
            directions = self.push_directions(node.child("push_directions"))
            ok &= directions is not None
            hints["push_directions"] = directions
        if node.has("max_nodes"):
            child = node.child("max_nodes")
            value = child.value
            if is_number(value) and isinstance(value, int) and value > 0:
                hints["max_nodes"] = int(value)
            else:
                self.error(child, f"expected a positive whole number, got {describe(value)}")
                ok = False
        return PlanningHints(**hints) if ok else None

    # -- the push controller --------------------------------------------------------------------
    def controller(self, root: Node) -> Controller | None:
        """The ``controller:`` mapping (``docs/problem-format.md``), converted to internal units:
        ``kp`` in mass/s^2 needs no conversion, ``speed`` is a length per second, ``force`` a
        mass x length/s^2, ``torque`` a mass x length^2/s^2 and ``kp_angle`` a torque per angle
        unit."""
        if not root.has("controller"):
            return DEFAULT_CONTROLLER
        node = root.child("controller")
        if not self.mapping(
            node, "a mapping {kind: compliant | servo, ...} (" + ", ".join(CONTROLLER_KEYS) + ")"
        ):
            return None
        ok = True
        for key_node, _ in node.entries():
            if key_node.value not in CONTROLLER_KEYS:
                # An error, not a warning: a misspelt gain would silently change the physics.
                self.error(
                    key_node,
                    f"unknown controller key {key_node.value!r}"
                    f"{suggest(key_node.value, CONTROLLER_KEYS)}; expected one of "
                    f"{', '.join(CONTROLLER_KEYS)}",
                )
                ok = False
        kinds = tuple(kind.value for kind in ControllerKind)
        kind: ControllerKind | None = DEFAULT_CONTROLLER.kind
        if node.has("kind"):
            kind_node = node.child("kind")
            if kind_node.value in kinds:
                kind = ControllerKind(kind_node.value)
            else:
                kind = None
                self.error(
                    kind_node, f"expected {' or '.join(kinds)}, got {describe(kind_node.value)}"
                )
        if kind is ControllerKind.SERVO:
            for key_node, _ in node.entries():
                if key_node.value in CONTROLLER_KEYS and key_node.value not in SERVO_KEYS:
                    self.error(
                        key_node,
                        f"{key_node.value!r} tunes the compliant controller only; the servo "
                        f"reads {', '.join(SERVO_KEYS)}",
                    )
                    ok = False
        length = self.units.length_factor
        scale = {
            "kp": 1.0,
            "kp_angle": length * length / self.units.angle_factor,
            "speed": length,
            "force": length,
            "torque": length * length,
        }
        values: dict[str, Any] = {}
        for key, factor in scale.items():
            if not node.has(key):
                continue
            child = node.child(key)
            value = self.number(child, f"a positive {key}")
            if value is None:
                ok = False
            elif value <= 0:
                self.error(child, f"expected a positive {key}, got {fmt(value)}")
                ok = False
            else:
                values[key] = value * factor
        if kind is None or not ok:
            return None
        return Controller(kind=kind, **values)

    def push_directions(self, node: Node) -> tuple[str, ...] | None:
        items = self.list_of(node, f"a non-empty list drawn from {', '.join(PUSH_DIRECTIONS)}")
        if items is None:
            return None
        chosen: list[str] = []
        ok = True
        for item in items:
            if item.value not in PUSH_DIRECTIONS:
                self.error(
                    item,
                    f"unknown push direction {describe(item.value)}; expected one "
                    f"of {', '.join(repr(d) for d in PUSH_DIRECTIONS)} (quoted)",
                )
                ok = False
            elif item.value in chosen:
                self.error(
                    item, f"push direction {item.value!r} is listed twice; list each at most once"
                )
                ok = False
            else:
                chosen.append(str(item.value))
        return tuple(chosen) if ok else None
