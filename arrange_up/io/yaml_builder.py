"""The YAML problem builder: a parsed ``.yaml`` file to an :class:`ArrangementProblem`.

:class:`ProblemBuilder` has one method per section of the format (``docs/problem-format.md``;
the rules are summarised in :mod:`arrange_up.io.yaml_problem`), each recording every problem it
finds in the report and returning ``None`` for what is invalid; :meth:`ProblemBuilder.build`
returns a problem only when the whole file is valid.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from arrange_up.io import validation
from arrange_up.io.validation import (
    MAX_LISTED_OVERLAPS,
    MAX_POSE_REACH,
    WIDE_SPREAD,
    Placed,
    pose_reach,
    too_many_objects,
)
from arrange_up.io.yaml_settings import (
    SettingsReader,
)
from arrange_up.io.yaml_shapes import MAX_PROBLEM_VERTICES, SHAPE_EXPECTED, ShapeReader
from arrange_up.io.yaml_source import (
    Node,
    NodeReader,
    Report,
    at,
    describe,
    fmt,
)
from arrange_up.model.problem import (
    WALL_EDGES,
    ArrangementProblem,
    Goal,
    InitialObject,
    ObjectKind,
    ObjectSpec,
    Pose,
    Shape,
    Table,
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
KIND_NAMES = tuple(kind.value for kind in ObjectKind)
#: The kinds that may start on the table (under 'initial'); obstacles are fixed under 'objects'.
_MOVABLE = (ObjectKind.PART, ObjectKind.MANIPULATOR, ObjectKind.FIXTURE)


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
    """Builds the problem of one parsed file, section by section (see the module docstring);
    shapes and the settings sections are read by their own readers into the same report."""

    def __init__(self, report: Report) -> None:
        super().__init__(report)
        self.shape_reader = ShapeReader(report)
        self.settings_reader = SettingsReader(report)

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
        self.shape_reader.units = self.settings_reader.units = self.units
        shapes = self.shape_reader.shapes(root)
        objects = self.objects(root, shapes)
        if objects is None:  # too many to check: the rest would be a flood of messages
            return None
        initial = self.initial(root, objects)
        self.check_spread(table, initial)
        self.check_placement(table, objects, initial)
        goal = self.goal(root, objects)
        uncertainty = self.settings_reader.uncertainty(root)
        planning = self.settings_reader.planning(root)
        controller = self.settings_reader.controller(root)

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
        self.check_goal_overlaps(root, problem)
        return problem

    def check_goal_overlaps(self, root: Node, problem: ArrangementProblem) -> None:
        """Parts that overlap at their nominal goal poses are a warning
        (:func:`~arrange_up.io.validation.goal_overlaps`), at the later part's goal pose."""
        goal = root.child("goal")
        poses = (
            goal.child("relative").child("poses")
            if problem.goal.is_relative
            else goal.child("poses")
        )
        nodes = {str(key.value): value for key, value in poses.entries()}
        scale = self.units.length_out(1.0) ** 2
        for a, b, area in validation.goal_overlaps(problem):
            self.report.warning(
                nodes[b],
                None,
                f"at their goal poses {a} and {b} overlap by {fmt(area * scale)} square "
                f"{self.units.length}: no plan reaches the nominal arrangement, only poses "
                "within the tolerance that separate them can meet the goal; expected goal "
                "poses at which the parts touch at most",
            )

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

    # -- objects --------------------------------------------------------------------------------
    def objects(self, root: Node, shapes: dict[str, Shape | None]) -> dict[str, _Object] | None:
        """The declared objects by name (an invalid one kept, marked not ok, so that its uses
        are not reported as undeclared); ``None`` after an error when the file declares more
        than :data:`~arrange_up.io.validation.MAX_OBJECTS`, before any of them is read."""
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
        refused = too_many_objects(len(node.value))
        if refused is not None:
            self.error(node, refused)
            return None
        for key_node, value_node in node.entries():
            name = key_node.value
            if not isinstance(name, str) or not NAME_PATTERN.fullmatch(name):
                if isinstance(name, str):
                    got = f"invalid object name {name!r}"
                else:
                    got = f"an object name must be a string, got {describe(name)}"
                self.error(
                    key_node,
                    f"{got}; expected an identifier: letters, digits, "
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
                f"{obj.kind.with_article}: give its starting pose under 'initial' (or leave "
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
            return self.shape_reader.shape_form(node, None)
        self.error(
            node,
            f"expected the name of a shape declared under 'shapes' or an inline "
            f"{SHAPE_EXPECTED}; got {describe(node.value)}",
        )
        return None

    def declared(
        self,
        key_node: Node,
        objects: dict[str, _Object],
        where: str,
        kinds: tuple[ObjectKind, ...],
        exclude: str | None = None,
    ) -> _Object | None:
        """The object a key names, or ``None`` after reporting an undeclared name. The report
        suggests only the names that would be valid here: declared objects of ``kinds`` with
        a valid name (and a kind that could be read), other than ``exclude``."""
        name = key_node.value
        if isinstance(name, str) and name in objects:
            return objects[name]
        shown = repr(name) if isinstance(name, str) else describe(name)
        valid = [
            o.name
            for o in objects.values()
            if o.kind in kinds and NAME_PATTERN.fullmatch(o.name) and o.name != exclude
        ]
        nouns = [f"{kind.value}s" for kind in kinds]
        noun = nouns[0] if len(nouns) == 1 else ", ".join(nouns[:-1]) + " and " + nouns[-1]
        other = " other than the reference" if exclude is not None else ""
        self.error(
            key_node,
            f"{shown} in {where} is not declared under 'objects'; "
            f"expected one of the declared {noun}{other} ({', '.join(valid) or 'none'})",
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
            obj = self.declared(key_node, objects, "'initial'", _MOVABLE)
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

    def check_spread(self, table: Table | None, initial: list[tuple[InitialObject, Node]]) -> None:
        """Refuse an initial position spread beyond
        :func:`~arrange_up.io.validation.pose_reach` (as a plan file's poses)."""
        if table is None:
            return
        limit = pose_reach(table.size)
        for entry, node in initial:
            if not node.is_map or not node.has("uncertainty"):
                continue
            items = node.child("uncertainty").items()
            for value, item in zip(entry.uncertainty[:2], items, strict=False):
                if value > limit:
                    self.error(
                        item,
                        f"half-width {fmt(item.value)} {self.units.length} is more than "
                        f"{MAX_POSE_REACH} table sizes; expected at most "
                        f"{fmt(limit / self.units.length_factor)} {self.units.length} "
                        f"({WIDE_SPREAD})",
                    )

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
        checks = validation.check_placement(
            [item for item, _ in placed], table_size, max_overlaps=MAX_LISTED_OVERLAPS + 1
        )

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
        listed = 0
        for (later, node), check in zip(placed, checks, strict=True):
            for index, overlap in check.overlaps:
                listed += 1
                if listed > MAX_LISTED_OVERLAPS:
                    self.error(
                        node,
                        f"{later.name} and more objects overlap at their nominal poses: only "
                        f"the first {MAX_LISTED_OVERLAPS} overlapping pairs are listed, the "
                        "others are not looked for; expected shapes that touch at most",
                    )
                    break
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
        obj = self.declared(node, objects, "'goal.relative.reference'", (ObjectKind.PART,))
        if obj is None:
            return None
        if obj.kind is None:
            return None
        if obj.kind is not ObjectKind.PART:
            self.error(
                node,
                f"the reference of a relative goal must be a part; {obj.name} is "
                f"{obj.kind.with_article}",
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
            obj = self.declared(key_node, objects, where, (ObjectKind.PART,), reference)
            if obj is not None and obj.kind is not None and obj.kind is not ObjectKind.PART:
                self.error(
                    key_node,
                    f"a goal for a non-part: {obj.name} is {obj.kind.with_article}; only "
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
