"""The arrangement problem: the one internal truth about a problem, as frozen dataclasses.

A problem file (``.yaml``, see ``docs/problem-format.md``; or ``.pddl``) is loaded into an
:class:`ArrangementProblem`. Everything downstream (geometry, physics, planning, evaluation)
reads only these classes.

Contracts that hold for every loaded problem:

* Lengths are in **inches** and angles in **radians**, whatever the file used; ``units`` records
  the file's units so results can be written back in them.
* A :class:`Shape` is a tuple of convex, counter-clockwise polygons in the object's own frame,
  translated so that the shape's area centroid is the frame origin (a pose refers to the
  centroid, as the format specifies).
* Collections are tuples (not dicts) so that problems are hashable and picklable, which worker
  processes need; the ``object``/``initial_of``/``goal.target`` helpers give keyed access.
* Everything is validated by the loader: names exist, kinds fit their roles, sizes and
  uncertainties are non-negative, initial shapes lie on the table without overlapping.
"""

from __future__ import annotations

import dataclasses
import enum
import functools
import hashlib
import json
import math
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field

from arrange_up.model.units import Units

Pose = tuple[float, float, float]
"""``(x, y, theta)``: inches, inches, radians, in the world (table) frame."""
HalfWidths = tuple[float, float, float]
"""``(dx, dy, dtheta)``: a symmetric pose interval's half-widths (inches, inches, radians)."""
Range = tuple[float, float]
"""``(low, high)`` of a uniformly drawn parameter."""
Point = tuple[float, float]
ConvexPolygon = tuple[Point, ...]

WALL_EDGES: tuple[str, ...] = ("left", "right", "bottom", "top")
STANDARD_GRAVITY = 386.09
"""Standard gravity in in/s^2: the table friction's normal force per unit mass."""


def as_triple(values: Iterable[float]) -> tuple[float, float, float]:
    """``values`` as a 3-tuple (a :data:`Pose` or :data:`HalfWidths`), each element as given;
    ``ValueError`` unless there are exactly three."""
    a, b, c = values
    return (a, b, c)


class ObjectKind(enum.StrEnum):
    """The role an object plays (thesis §1.2.1): parts are arranged, manipulators push,
    fixtures are movable obstacles the planner may place and pick, obstacles never move."""

    PART = "part"
    MANIPULATOR = "manipulator"
    FIXTURE = "fixture"
    OBSTACLE = "obstacle"

    @property
    def with_article(self) -> str:
        """The kind's name with its indefinite article, for messages ("a part", "an obstacle")."""
        return f"{'an' if self.value[0] in 'aeiou' else 'a'} {self.value}"


@dataclass(frozen=True)
class Shape:
    """A rigid 2-D shape as a set of convex polygons.

    ``parts`` are convex and counter-clockwise, in the object frame with the area centroid at
    the origin. ``box`` is ``(width, height)`` when the shape was given as a box (useful to the
    block-world transition models and to manipulators); ``name`` is the name it was declared
    under in ``shapes:``, or ``None`` for an inline shape.
    """

    parts: tuple[ConvexPolygon, ...]
    box: tuple[float, float] | None = None
    name: str | None = None

    def vertices(self) -> Iterator[Point]:
        for part in self.parts:
            yield from part

    @property
    def radius(self) -> float:
        """Largest distance of any vertex from the pose origin (the centroid)."""
        return max(math.hypot(x, y) for x, y in self.vertices())

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """Axis-aligned bounds ``(xmin, ymin, xmax, ymax)`` in the object frame."""
        xs = [x for x, _ in self.vertices()]
        ys = [y for _, y in self.vertices()]
        return (min(xs), min(ys), max(xs), max(ys))

    @property
    def area(self) -> float:
        total = 0.0
        for poly in self.parts:
            n = len(poly)
            total += 0.5 * sum(
                poly[i][0] * poly[(i + 1) % n][1] - poly[(i + 1) % n][0] * poly[i][1]
                for i in range(n)
            )
        return total


@dataclass(frozen=True)
class ObjectSpec:
    """One declared object. ``pose`` is set for obstacles (which never move) and only for them."""

    name: str
    kind: ObjectKind
    shape: Shape
    pose: Pose | None = None

    @property
    def push_direction(self) -> Point:
        """Unit push direction in the object's frame (meaningful for manipulators).

        A manipulator pushes perpendicular to its long side (thesis §2.1.3). For a shape wider
        than tall (like the 2.5 x 0.15 in paddle) that is the frame's +y axis, which is the
        thesis's ``theta + pi/2``; for a shape taller than wide it is -x, i.e. the long side's
        direction rotated by +90 degrees in both cases.
        """
        xmin, ymin, xmax, ymax = self.shape.extent
        return (0.0, 1.0) if (xmax - xmin) >= (ymax - ymin) else (-1.0, 0.0)


@dataclass(frozen=True)
class InitialObject:
    """An object on the table at the start: nominal pose and the half-widths of its interval."""

    name: str
    pose: Pose
    uncertainty: HalfWidths = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Goal:
    """The goal arrangement (thesis §2.1.4).

    ``targets`` pairs each constrained part with its target pose. For an absolute goal
    (``reference is None``) targets are world poses; for a relative goal they are poses in the
    frame of the ``reference`` part, which may end anywhere. ``tolerance`` gives half-widths;
    its angle is ``None`` when any orientation is acceptable.
    """

    targets: tuple[tuple[str, Pose], ...]
    tolerance: tuple[float, float, float | None]
    reference: str | None = None

    @property
    def is_relative(self) -> bool:
        return self.reference is not None

    @functools.cached_property
    def parts(self) -> tuple[str, ...]:
        # cached: the planner's action generator and heuristics ask for it per candidate
        return tuple(name for name, _ in self.targets)

    @functools.cached_property
    def _target_of(self) -> dict[str, Pose]:
        return dict(reversed(self.targets))  # a part listed twice: its first target

    def target(self, name: str) -> Pose:
        try:
            return self._target_of[name]
        except KeyError:
            raise KeyError(name) from None


@dataclass(frozen=True)
class Uncertainty:
    """Nondeterminism of actions and of the world (all optional in a file).

    Defaults describe a deterministic world at the nominal parameters (the middles of the
    ranges of thesis Table 4.2): an omitted key adds no noise.
    """

    place: HalfWidths = (0.0, 0.0, 0.0)
    push: HalfWidths = (0.0, 0.0, 0.0)
    friction: Range = (0.5, 0.5)
    part_density: Range = (0.125, 0.125)
    manipulator_density: Range = (0.4, 0.4)


@dataclass(frozen=True)
class PlanningHints:
    """Optional ``planning:`` hints refining the action generators and search limits.

    ``None`` means "use the planner's default"; the planner documents its defaults.
    ``place_offsets`` are ``(dx, dy)`` offsets from a goal target for candidate place poses
    (inches); ``push_distances`` are candidate push distances (inches); ``push_directions`` a
    subset of ``("+x", "-x", "+y", "-y")``; ``max_nodes`` the node limit of the search.
    """

    place_offsets: tuple[Point, ...] | None = None
    place_angles: tuple[float, ...] | None = None
    push_distances: tuple[float, ...] | None = None
    push_directions: tuple[str, ...] | None = None
    max_nodes: int | None = None


class ControllerKind(enum.StrEnum):
    """How the robot drives a pushing manipulator (``controller.kind`` in a problem file)."""

    COMPLIANT = "compliant"
    """The thesis's controller (§2.4.1, §2.4.2): a low-gain clipped PD per axis and on the
    angle, tracking a set point that moves along the push line at the push speed; a resisted
    push stops short."""
    SERVO = "servo"
    """A stiff, speed-limited position servo (a position-controlled arm): a push ends where it
    was sent unless the force clip or a wall stops it."""


@dataclass(frozen=True)
class Controller:
    """The push controller (``controller:`` in a problem file), in internal units: inches,
    seconds, radians, mass in the problem's mass unit (density x square inch), force in mass x
    in/s^2.

    ``None`` means the documented default (see :mod:`arrange_up.physics.simulation`):
    ``speed`` the physics settings' push speed (3 in/s), ``force`` the problem's force clip
    (:func:`arrange_up.physics.settings.push_force`), ``kp_angle`` ``kp * r^2`` with ``r`` the
    paddle's radius (the largest distance of its outline from its centroid: a force at its end
    moves the end about as far by turning the paddle as a force at its centre moves the
    centre) and ``torque`` ``force * r`` (the force clip at the paddle's end). ``kp``,
    ``kp_angle`` and ``torque`` are used by ``compliant`` only.
    """

    kind: ControllerKind = ControllerKind.COMPLIANT
    kp: float = 300.0
    """Proportional gain per axis (mass/s^2: force per inch of tracking error)."""
    kp_angle: float | None = None
    """Proportional gain on the angle (mass x in^2/s^2 per radian)."""
    speed: float | None = None
    """Speed of the set point along the push line (in/s); for ``servo`` its speed limit."""
    force: float | None = None
    """Clip of the force on each axis (mass x in/s^2); for ``servo`` on its magnitude."""
    torque: float | None = None
    """Clip of the torque (mass x in^2/s^2)."""


DEFAULT_CONTROLLER = Controller()
"""The controller of a problem that names none (and of every PDDL problem): the compliant one
at its documented defaults (the measurements that chose them are in
docs/design/physics-controller.md)."""

SERVO_CONTROLLER = Controller(kind=ControllerKind.SERVO)
"""The servo at its defaults: the controller of every problem before problems named one (and
the default until the compliant controller replaced it). Plan files and records that name no
controller were made with it."""


@dataclass(frozen=True)
class Table:
    """The manipulation surface: ``[0, width] x [0, depth]`` with rigid walls on some edges."""

    size: tuple[float, float]
    walls: tuple[str, ...] = WALL_EDGES

    @property
    def width(self) -> float:
        return self.size[0]

    @property
    def depth(self) -> float:
        return self.size[1]


@dataclass(frozen=True)
class ArrangementProblem:
    """A conformant arrangement problem (thesis §1.2.2), in inches and radians."""

    name: str
    table: Table
    objects: tuple[ObjectSpec, ...]
    initial: tuple[InitialObject, ...]
    goal: Goal
    uncertainty: Uncertainty = field(default_factory=Uncertainty)
    planning: PlanningHints = field(default_factory=PlanningHints)
    controller: Controller = DEFAULT_CONTROLLER
    description: str = ""
    units: Units = field(default_factory=Units)
    source: str | None = None
    """Where the problem was read from (a path or ``domain:NAME``), for messages only."""

    # -- keyed access --------------------------------------------------------------------------
    def object(self, name: str) -> ObjectSpec:
        for spec in self.objects:
            if spec.name == name:
                return spec
        raise KeyError(f"problem {self.name!r} declares no object {name!r}")

    def initial_of(self, name: str) -> InitialObject | None:
        for entry in self.initial:
            if entry.name == name:
                return entry
        return None

    def of_kind(self, kind: ObjectKind) -> tuple[ObjectSpec, ...]:
        return tuple(spec for spec in self.objects if spec.kind is kind)

    @property
    def parts(self) -> tuple[ObjectSpec, ...]:
        return self.of_kind(ObjectKind.PART)

    @property
    def manipulators(self) -> tuple[ObjectSpec, ...]:
        return self.of_kind(ObjectKind.MANIPULATOR)

    @property
    def fixtures(self) -> tuple[ObjectSpec, ...]:
        return self.of_kind(ObjectKind.FIXTURE)

    @property
    def obstacles(self) -> tuple[ObjectSpec, ...]:
        return self.of_kind(ObjectKind.OBSTACLE)

    @property
    def put_away(self) -> tuple[str, ...]:
        """The fixtures that start off the table, in declaration order: the format's rule is
        that they must be off it again when the goal is reached (a fence put down is picked
        up); a fixture that starts on the table may stay."""
        return tuple(spec.name for spec in self.fixtures if self.initial_of(spec.name) is None)


def driven_by(problem: ArrangementProblem, kind: ControllerKind | str) -> ArrangementProblem:
    """``problem`` driven by a controller of ``kind`` (``"compliant"`` or ``"servo"``):
    ``problem`` itself when its controller already is of that kind (its own gains kept),
    else ``problem`` with that controller at its defaults. Raises ``ValueError`` for an
    unknown kind."""
    try:
        kind = ControllerKind(kind)
    except ValueError:
        known = ", ".join(k.value for k in ControllerKind)
        raise ValueError(f"unknown controller kind {kind!r}; expected one of {known}") from None
    if problem.controller.kind is kind:
        return problem
    return dataclasses.replace(problem, controller=Controller(kind=kind))


def problem_hash(problem: ArrangementProblem) -> str:
    """A content hash of what the planner sees: ``"sha256:<hex>"``.

    It covers the name, table, objects, initial belief, goal, uncertainty, planning hints and
    controller in internal units, with numbers rounded to 9 significant digits, so the same
    problem written in other units or in another format (``.yaml`` or ``.pddl``) hashes the
    same. The description, the file's units and its location are not part of the content; nor
    is the controller when it is :data:`SERVO_CONTROLLER`, the controller every problem had
    before problems named one: a servo problem hashes as it did then, so plan files and records
    made then still match the problem they were made for, and no longer match the same file
    under today's default controller.
    """

    def canonical(value: object) -> object:
        if dataclasses.is_dataclass(value) and not isinstance(value, type):
            return {
                f.name: canonical(getattr(value, f.name))
                for f in dataclasses.fields(value)
                if f.name not in ("description", "units", "source")
                and not (f.name == "controller" and getattr(value, f.name) == SERVO_CONTROLLER)
            }
        if isinstance(value, enum.Enum):
            return value.value
        if isinstance(value, tuple | list):
            return [canonical(v) for v in value]
        if isinstance(value, float):
            rounded = float(f"{value:.9g}")
            return 0.0 if rounded == 0 else rounded
        return value

    text = json.dumps(canonical(problem), sort_keys=True, separators=(",", ":"))
    return "sha256:" + hashlib.sha256(text.encode("utf-8")).hexdigest()
