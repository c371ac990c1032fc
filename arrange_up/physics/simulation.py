"""Top-down rigid-body physics of place, push and pick (thesis §2.1.3, §2.4.1), on pymunk.

Only the physics room imports pymunk: this module (the space, the controller, rest) and
:mod:`~arrange_up.physics.bodies` (the shapes compiled once per problem); the settings are in
:mod:`~arrange_up.physics.settings`. The room's face is one function::

    simulate(problem, state, action, noise=None, settings=DEFAULT_SETTINGS) -> StepOutcome

(a sequence of actions under drawn noise is run by :mod:`arrange_up.evaluation.rollouts`, which
also judges failures). Everything is in inches, seconds and radians; a body's mass is its areal
density times its area (so a 1-inch block of density 0.125 has mass 0.125) and forces are in
mass-inches per second squared.

Actions
=======
* **Place** writes the placed pose (commanded pose + ``noise.pose_offset``) and simulates
  nothing: the planner's precondition guarantees the placed object overlaps nothing.
* **Pick** removes the object.
* **Push** (thesis §2.4.1) builds a fresh space, writes the state, puts the manipulator down at
  the approach pose (commanded + ``noise.pose_offset``), runs ``settle_steps`` steps (a landing
  deeper than ``overlap_tolerance``, in the contacts or the geometry, is ``OVERLAP``), drives it
  toward the reference point ``distance`` inches along its push direction until it stops moving,
  stops driving it, waits until every other body is at rest, and lifts it off.

Model
=====
* **Bodies.** A movable object in the state is a dynamic body of mass ``density * area`` and
  moment ``sum(moment_for_poly(density * area_i, part_i))`` over its convex parts (the parts are
  centred on the shape's centroid, which is the body origin). Parts use
  ``noise.part_density``; a manipulator resting on the table uses ``noise.manipulator_density``.
* **Fixtures** are clamped to the table while they are on it: kinematic bodies that nothing can
  move. A fixture is a movable obstacle the robot places to push parts *against* (thesis ch. 4,
  Figure 4-1); a fixture as light as a part would just be pushed along with it.
  Mass and moment are set explicitly (shape density would leave rounding in the centre of
  gravity and break bit-identical replay).
* **Table friction** is pymunk's "tank" pattern: a ``PivotJoint`` and a ``GearJoint`` from each
  movable body to the static body, both with ``max_bias = 0`` (they only resist motion); the
  pivot's ``max_force`` is ``mu m g`` (Coulomb sliding friction) and the gear's is
  ``mu g rho integral(|r| dA)`` (the torque of Coulomb friction on a body spinning about its
  centroid, computed in closed form per convex part).
* **Contact friction.** One coefficient ``mu = noise.friction`` holds for every pair of
  surfaces: table, part-part, part-wall, part-paddle. pymunk multiplies the two shapes'
  friction values, so every shape gets ``sqrt(mu)``. Elasticity is 0 (wood and acrylic blocks
  do not bounce noticeably at a few inches per second).
* **Walls** (``table.walls``) are ``wall_thickness``-inch static boxes just outside the table
  edges, long enough to close the corners; edges without a wall are open, so a part can leave
  the table there (reported as ``OFF_TABLE`` when its centroid ends outside the table).
  Obstacles are static polygons at their poses.
* **The manipulator** (paddle) has mass ``manipulator_density * area`` and infinite moment (the
  robot holds it; it cannot turn) and **no table friction**: the robot carries it, so the drive
  alone moves it.
* **After the drive stops** the controller no longer pushes: its force toward the reference is
  zero. The robot still holds the paddle, though, so it becomes a *brake* (the same joint with
  ``max_bias = 0``: it resists being moved, up to the force clip, and pulls nowhere) until the
  other bodies are at rest; then the paddle is removed. The thesis's literal alternative, a
  paddle left free, is rejected: released from a chain compressed against a wall, the light
  frictionless paddle is kicked back by the contact solver's warm-started impulses, so the
  blocks spring apart, an artefact; with the brake, blocks end touching (overlaps within the
  slop). Figures: ``docs/design/physics.md``.

The push controller (servo)
===========================
With ``problem.controller.kind == "servo"`` (the compliant controller below is the default). The
thesis drives the paddle
with a clipped PD controller toward the reference point
``ref = approach + distance * push_direction``::

    F = clip(Kp (ref - x) - Kd v),   Kd = sqrt(4 m Kp)  (critically damped).

Here it runs on pymunk's C side as one ``PivotJoint`` between the static body (anchor at
``ref``) and the paddle (anchor at its centroid), with

* ``max_force = push_force``: the force clip (pymunk clamps the impulse vector's length, so the
  clip is on the force's magnitude rather than per axis);
* ``max_bias = push_speed``: the speed limit;
* ``error_bias = (1 - rate dt) ** (1 / dt)``, which makes the joint's target velocity exactly
  ``rate * (ref - x)`` per step, with ``rate = 1 / (4 damping_ratio**2 dt)``.

Each step the joint applies the impulse that brings the paddle's velocity to
``clamp(rate (ref - x), push_speed)``, clamped to ``push_force * dt``. For the paddle alone that
is, exactly (same floating-point recurrence, see ``tests/physics/test_physics.py``), the
semi-implicit Euler step of ``F = clip(Kd (clamp(Kp/Kd (ref - x), v_max) - v))`` with

    Kd = m / dt,   Kp = rate * Kd = m / (4 damping_ratio**2 dt**2),

i.e. the thesis's clipped PD with ``Kd = sqrt(4 m Kp)`` when ``damping_ratio = 1`` (the
default), written in the usual cascade form so that the speed limit caps the desired velocity.
The gains grow as ``1 / dt`` and ``1 / dt**2``: a stiff position servo, as a robot arm is (their
values at the default step: ``docs/design/physics-controller.md``, "The servo's gains"). With
these gains the velocity loop is dead-beat in discrete time and the position error then shrinks by
``1 - rate dt = 3/4`` per step: no overshoot, no oscillation.

*Where it differs from a fixed-gain PD:* in contact, the joint is solved together with the
contacts, so its derivative gain is the dead-beat one for everything the paddle is moving (the
paddle plus the parts it pushes), not for the paddle alone. It therefore keeps the commanded
speed while pushing and stalls only when the push needs more than ``push_force`` (or meets a
wall), whereas a PD with the paddle's own gains would stall once ``Kp * error`` falls below the
resistance. The thesis's observation that a push stops short when it collides holds in both.

Defaults (:mod:`~arrange_up.physics.settings`): ``push_speed`` is a careful robot push whose
travel per step stays far below the tunnelling limit of 1-inch blocks, and ``push_force`` pushes
a chain of 7 blocks at the highest friction and density of the thesis's ranges and still stalls
against a wall instead of crushing through it. A problem of heavier parts raises the clip to 1.5
times the friction of all its parts at its nominal (mid-range) friction and density
(:func:`push_force`); its heaviest draws can still stall the push, as the thesis's low-gain
controller stalled. The figures behind both: ``docs/design/physics-controller.md``.

The compliant controller
========================
With ``problem.controller.kind == "compliant"`` (:class:`~arrange_up.model.problem.Controller`)
the push runs the thesis's controller faithfully (§2.4.1): before every step the paddle gets the
force and torque

    F_x = clip(Kp (x_ref(t) - x) - Kd v_x),   F_y likewise,   Kd = sqrt(4 m Kp),
    tau = clip(Kp_angle (theta_0 - theta) - Kd_angle omega),   Kd_angle = sqrt(4 I Kp_angle),

(each axis clipped at ``force``, the torque at ``torque``; ``damping_ratio`` scales both Kd),
where the set point ``x_ref(t)`` moves from the approach pose along the push line at ``speed``
and stops ``distance`` along it: the thesis's real robot fed its low-gain controller
intermediate set points along the pushing line, updated with time (§2.4.2). A PD toward the
distant end point with no speed limit would be a catapult (it throws blocks:
``docs/design/physics-controller.md``). The paddle has its own moment here (a compliant
wrist turns when a part meets it off-centre) and still no table friction. The drive runs until
the set point has stopped and the paddle has been still (position and angle) for
``rest_checks`` checks; then the robot holds the paddle (a pivot and a gear joint with no bias,
clipped at ``force`` and ``torque``: the brake) until the other bodies are at rest. Under the
low gain a resisted push stops short by about the resisting friction / Kp, growing with friction
x mass; a free push ends at its target without overshoot (semi-implicit Euler of a critically
damped PD with ``sqrt(Kp / m) dt`` well below 1). Defaults (``Kp = 300``) and their measurements:
``docs/design/physics-controller.md``. With ``PhysicsSettings.compliant_in_solver`` the same PD,
set point and clips are built from constraints the engine solves (:class:`_SolverTracking`), not
set from Python before every step.

Rest
====
Rest is judged from pose change, not velocity (bodies being separated move while reporting zero
velocity): every ``rest_interval`` of simulated time each body's pose is compared with
the previous check; a body is still when it moved less than ``rest_linear_tol`` inches and
``rest_angular_tol`` radians. The drive stops when the paddle was still ``rest_checks``
checks in a row; the push ends when every other body was still ``rest_checks`` checks in a row,
at least one of them after the drive stopped (the other bodies are watched from the first
check at which the paddle is still, so the check that stops the drive can count: that saves
one interval per push and still ends every push with two consecutive still checks of every
body). A compliant push not at rest ``stuck_time`` (1 s) after its set point's end is solved
with ``stuck_iterations`` (20) from then on: a paddle that has turned and presses a tilted part
into a wall or a post wedges it, and at 5 or 10 iterations that wedge chatters until the cap
(the servo keeps its iterations throughout). From then on its drive also ends once the paddle
has advanced along the push by less than the rest speed over ``stall_window`` (0.5 s): a wedge
that still chatters, the paddle rocking or creeping sideways with the part along a wall,
never passes the check-to-check rest test. The whole push is capped at ``max_time`` (20 s) of
simulated time, or ``travel_margin`` (10 s) after its set point's end when that is later (a push
longer than about 30 in at the default speed); a cap hit is reported as ``NOT_AT_REST`` with
the poses at the cap, never silently truncated.

These rest settings, the solver ``iterations`` and body sleeping (``sleep_time``: bodies idle
that long are no longer solved until something touches them) are chosen per controller
(:meth:`PhysicsSettings.for_controller`, :data:`~arrange_up.physics.settings.CONTROLLER_VALUES`):
the servo keeps the values every push had before (a check every 0.1 s, two checks, 10
iterations, no sleeping), so that its plans and measurements stay reproducible bit for bit; the
compliant controller's were chosen on the accuracy benchmark ``benchmarks/push_accuracy.py``
(``docs/design/physics.md``).

Overlaps beyond the slop are pushed apart at 20% per step (``collision_bias``, Box2D's
Baumgarte factor) rather than pymunk's default 2.6%: a chain that hits a wall at 3 in/s is
squeezed by the solver, and at the default rate its slow re-expansion against the paddle keeps
the paddle creeping for most of a second.

The defaults' accuracy (against a finer step) and every other figure behind them are in
``docs/design/physics.md`` (the controllers' in ``docs/design/physics-controller.md``), with
the commands that reproduce them.

Determinism and speed
=====================
A fresh space is built per push, in a fixed order (walls, obstacles, movable bodies in state
order, the manipulator), with explicit masses, so the same inputs give bit-identical results in
any process (a reused space does not).

Speed is first-class: pushes are simulated millions of times by the planners. The space is
built and stepped through pymunk's cffi binding (``pymunk._chipmunk_cffi.lib``, the C functions
the pymunk classes wrap) rather than through the Python classes, whose per-object bookkeeping
costs more than the simulation itself for small scenes; the controller runs entirely in C, so a
step is one C call; Python looks at the bodies only every ``rest_interval`` (timings:
``docs/design/physics.md``). Everything built is freed explicitly (``try``/``finally``).
``pymunk._chipmunk_cffi`` is not public API (``pymunk.batch`` uses it too); pyproject pins
pymunk ~= 7.3 and the tests exercise every call made here.
"""

from __future__ import annotations

import enum
import math
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import NamedTuple

# pymunk's cffi binding: the Chipmunk2D C API that pymunk's classes wrap (pymunk ~= 7.3).
from pymunk._chipmunk_cffi import ffi, lib

from arrange_up.geometry.se2 import rotate
from arrange_up.model.problem import (
    ArrangementProblem,
    Controller,
    ControllerKind,
    ObjectKind,
    Pose,
    Table,
)
from arrange_up.model.world import (
    Action,
    ActionNoise,
    Pick,
    Place,
    Push,
    WorldState,
    nominal_noise,
)
from arrange_up.physics.bodies import _IDENTITY, _compile, _Compiled
from arrange_up.physics.settings import (
    DEFAULT_SETTINGS,
    PhysicsSettings,
    _force_clip,
    pd_gains,
    push_crossing,
    push_force,
)

__all__ = [
    "DEFAULT_SETTINGS",
    "PhysicsSettings",
    "StepOutcome",
    "SimulationStatus",
    "pd_gains",
    "CompliantGains",
    "compliant_gains",
    "push_force",
    "simulate",
    "simulate_watched",
    "StiffManipulator",
    "stiff_manipulators",
    "STABLE_RATE",
]


# ----------------------------------------------------------------------------------------------
# Outcome
# ----------------------------------------------------------------------------------------------


class SimulationStatus(enum.StrEnum):
    """How an action's simulation ended. Anything but ``OK`` makes the outcome unreliable."""

    OK = "ok"
    """Every body came to rest on the table."""
    NOT_AT_REST = "not_at_rest"
    """The ``max_time`` cap was hit before everything came to rest (poses are those at the
    cap)."""
    OFF_TABLE = "off_table"
    """Everything came to rest, but the centroid of at least one object (listed in
    ``off_table``) is outside the table rectangle: it would have fallen off."""
    OVERLAP = "overlap"
    """When the push started, shapes overlapped by more than ``overlap_tolerance`` (an invalid
    state or approach pose); the simulation was still run, but means little."""


@dataclass(frozen=True)
class StepOutcome:
    """The result of simulating one action.

    ``state`` holds the poses after the action (for a pick the object is removed, for a place
    the placed pose is the commanded pose plus the noise offset, for a push the poses at rest,
    or at the cap). Angles are continuous: a body's theta is its initial theta plus the
    rotation it made (not wrapped). ``status`` takes the first that applies of ``OVERLAP``,
    ``NOT_AT_REST``, ``OFF_TABLE``, ``OK``. ``sim_time`` and ``steps`` count the simulated time
    and physics steps (0 for place and pick); ``manipulator_travel`` is how far the paddle moved
    along its push direction while it was driven (in); ``overlap`` the deepest overlap between
    shapes when the push started (in, 0 when none). ``manipulator_pose`` is the paddle's pose
    when the push ended, just before it is lifted off (what a robot's joint encoders report
    after the push; ``None`` for place and pick).
    """

    state: WorldState
    status: SimulationStatus = SimulationStatus.OK
    off_table: tuple[str, ...] = ()
    sim_time: float = 0.0
    steps: int = 0
    manipulator_travel: float = 0.0
    overlap: float = 0.0
    manipulator_pose: Pose | None = None

    @property
    def ok(self) -> bool:
        return self.status is SimulationStatus.OK


# ----------------------------------------------------------------------------------------------
# Simulation
# ----------------------------------------------------------------------------------------------


def simulate(
    problem: ArrangementProblem,
    state: WorldState,
    action: Action,
    noise: ActionNoise | None = None,
    settings: PhysicsSettings = DEFAULT_SETTINGS,
) -> StepOutcome:
    """Simulate one action from ``state`` (see the module docstring for the model).

    ``noise`` defaults to the noise-free draw (:func:`arrange_up.model.world.nominal_noise`).
    Raises :class:`ValueError` for an invalid call: unknown names, a state listing an obstacle
    or an object twice, placing an object already on the table (or one that is not a part or a
    fixture), picking one that is not on the table, pushing with an object that is not a
    manipulator or that is on the table, a negative or non-finite push distance.
    """
    compiled = _compile(problem, settings.wall_thickness)
    _check_state(compiled, state)
    if noise is None:
        noise = nominal_noise(problem)
    if isinstance(action, Push):
        return _push(compiled, state, action, noise, settings)
    if isinstance(action, Place):
        return _place(compiled, state, action, noise)
    if isinstance(action, Pick):
        return _pick(compiled, state, action)
    raise ValueError(f"unknown action {action!r}: expected Place, Push or Pick")


def _check_state(compiled: _Compiled, state: WorldState) -> None:
    bodies = compiled.bodies
    names = [name for name, _ in state.poses]
    for name in names:
        if name not in bodies:
            if any(spec.name == name for spec in compiled.problem.objects):
                raise ValueError(f"obstacle {name!r} cannot be in a world state (it never moves)")
            raise ValueError(f"unknown object {name!r} in the world state")
    if len(set(names)) != len(names):
        raise ValueError(f"world state lists an object twice: {names}")


def _spec_kind(compiled: _Compiled, name: str, role: str) -> ObjectKind:
    body = compiled.bodies.get(name)
    if body is not None:
        return body.kind
    if any(spec.name == name for spec in compiled.problem.objects):
        return ObjectKind.OBSTACLE
    raise ValueError(f"{role}: unknown object {name!r} in problem {compiled.problem.name!r}")


def _off_table(table: Table, poses: Sequence[tuple[str, Pose]]) -> tuple[str, ...]:
    w, d = table.width, table.depth
    return tuple(name for name, (x, y, _) in poses if not (0.0 <= x <= w and 0.0 <= y <= d))


def _finish(
    compiled: _Compiled, poses: tuple[tuple[str, Pose], ...], status: SimulationStatus, **kw
) -> StepOutcome:
    off = _off_table(compiled.table, poses)
    if status is SimulationStatus.OK and off:
        status = SimulationStatus.OFF_TABLE
    return StepOutcome(WorldState(poses), status, off, **kw)


def _place(
    compiled: _Compiled, state: WorldState, action: Place, noise: ActionNoise
) -> StepOutcome:
    kind = _spec_kind(compiled, action.obj, "place")
    if kind not in (ObjectKind.PART, ObjectKind.FIXTURE):
        raise ValueError(
            f"place: {action.obj!r} is a {kind.value}; only parts and fixtures are "
            "placed (a manipulator is put down by a push)"
        )
    if action.obj in state:
        raise ValueError(f"place: {action.obj!r} is already on the table")
    dx, dy, dth = noise.pose_offset
    x, y, th = action.pose
    placed = (float(x) + dx, float(y) + dy, float(th) + dth)
    mapping = state.as_dict()
    mapping[action.obj] = placed
    order = [spec.name for spec in compiled.problem.objects if spec.name in mapping]
    poses = tuple((name, mapping[name]) for name in order)
    return _finish(compiled, poses, SimulationStatus.OK)


def _pick(compiled: _Compiled, state: WorldState, action: Pick) -> StepOutcome:
    if _spec_kind(compiled, action.obj, "pick") is ObjectKind.OBSTACLE:
        raise ValueError(f"pick: {action.obj!r} is an obstacle (obstacles never move)")
    if action.obj not in state:
        raise ValueError(f"pick: {action.obj!r} is not on the table")
    poses = tuple((name, pose) for name, pose in state.poses if name != action.obj)
    return _finish(compiled, poses, SimulationStatus.OK)


def _add_drive(
    space,
    static,
    paddle,
    ref: tuple[float, float],
    settings: PhysicsSettings,
    force: float,
    speed: float | None = None,
):
    """The servo of the push as a pivot joint, clipped at ``force``, its speed limited to
    ``speed`` (``settings.push_speed`` when ``None``; module docstring)."""
    joint = lib.cpPivotJointNew2(static, paddle, ref, (0.0, 0.0))
    lib.cpConstraintSetMaxForce(joint, force)
    lib.cpConstraintSetMaxBias(joint, settings.push_speed if speed is None else speed)
    lib.cpConstraintSetErrorBias(
        joint, (1.0 - settings.approach_rate * settings.dt) ** (1.0 / settings.dt)
    )
    lib.cpSpaceAddConstraint(space, joint)
    return joint


def _push(
    compiled: _Compiled,
    state: WorldState,
    action: Push,
    noise: ActionNoise,
    s: PhysicsSettings,
    watch: Callable[[list], None] | None = None,
) -> StepOutcome:
    """Simulate the push ``action`` from ``state`` under ``noise`` (module docstring): build a
    fresh space, put the paddle down and settle, drive it until it is still, hold it until
    every other body is at rest (or the cap), and read the poses; everything built is freed.

    The phases are :func:`_check_push`, :class:`_Scene` with :func:`_add_movable_bodies` and
    :func:`_put_down_paddle`, :func:`_settle`, :func:`_start_drive` and :class:`_PushRun`
    (:meth:`~_PushRun.drive_until_still`, then :meth:`~_PushRun.hold_until_rest`). ``watch``,
    when given, is called after every step (:func:`simulate_watched`).
    """
    distance = _check_push(compiled, state, action, noise)
    controller = compiled.problem.controller
    s = s.for_controller(controller.kind)
    compliant = controller.kind is ControllerKind.COMPLIANT
    scene = _Scene(math.sqrt(float(noise.friction)))
    try:
        scene.configure(s)
        scene.add_statics(compiled.statics)
        movable = _add_movable_bodies(scene, compiled, state, noise, s)
        paddle = _put_down_paddle(
            scene, compiled.bodies[action.manipulator], action, noise, compliant
        )
        step = lib.cpSpaceStep if watch is None else _watched_step(watch, scene.bodies)
        overlap = _settle(scene, compiled, state, action.manipulator, paddle.pose, s, step)
        drive = _start_drive(scene, compiled, controller, paddle, distance, s, step)
        run = _PushRun(scene, compiled, paddle, drive, movable, distance, s, step, watch)
        if run.drive_until_still():
            run.hold_until_rest()
        poses = []
        for (obj, _), b in zip(state.poses, movable, strict=True):
            pos = lib.cpBodyGetPosition(b)
            poses.append((obj, (pos.x, pos.y, lib.cpBodyGetAngle(b))))
        pos = lib.cpBodyGetPosition(paddle.body)
        paddle_pose = (pos.x, pos.y, lib.cpBodyGetAngle(paddle.body))
    finally:
        scene.free()

    if overlap > s.overlap_tolerance:
        status = SimulationStatus.OVERLAP
    elif run.capped:
        status = SimulationStatus.NOT_AT_REST
    else:
        status = SimulationStatus.OK
    return _finish(
        compiled,
        tuple(poses),
        status,
        sim_time=run.steps * s.dt,
        steps=run.steps,
        manipulator_travel=run.travel,
        overlap=overlap,
        manipulator_pose=paddle_pose,
    )


def _check_push(compiled: _Compiled, state: WorldState, action: Push, noise: ActionNoise) -> float:
    """The push's distance, after refusing an invalid push with :class:`ValueError`: a pusher
    that is not a manipulator or is on the table, a negative or non-finite distance, a
    non-finite approach pose, an invalid noise draw."""
    name = action.manipulator
    kind = _spec_kind(compiled, name, "push")
    if kind is not ObjectKind.MANIPULATOR:
        raise ValueError(f"push: {name!r} is a {kind.value}, not a manipulator")
    if name in state:
        raise ValueError(f"push: manipulator {name!r} is already on the table")
    distance = float(action.distance)
    if not (math.isfinite(distance) and distance >= 0.0):
        raise ValueError(f"push: distance must be finite and non-negative, got {distance!r}")
    if not all(math.isfinite(v) for v in action.pose):
        raise ValueError(f"push: approach pose must be finite, got {action.pose!r}")
    _check_noise(noise)
    return distance


class _Scene:
    """The pymunk space of one push and every C object added to it, which :meth:`free` frees
    (the space does not own its bodies, shapes and constraints). Every shape gets the friction
    ``shape_mu`` (the square root of the draw's coefficient: pymunk multiplies the two)."""

    def __init__(self, shape_mu: float) -> None:
        self.space = lib.cpSpaceNew()
        self.shape_mu = shape_mu
        self.shapes: list = []
        self.constraints: list = []
        self.bodies: list = []
        self.static = None

    def configure(self, s: PhysicsSettings) -> None:
        """Set the solver (iterations, slop, bias) and sleeping of ``s``; fetch the static
        body."""
        space = self.space
        lib.cpSpaceSetIterations(space, s.iterations)
        lib.cpSpaceSetCollisionSlop(space, s.collision_slop)
        lib.cpSpaceSetCollisionBias(space, s.collision_bias)
        if s.sleep_time > 0.0:
            lib.cpSpaceSetSleepTimeThreshold(space, s.sleep_time)
            lib.cpSpaceSetIdleSpeedThreshold(space, s.rest_linear_tol / s.rest_interval)
        self.static = lib.cpSpaceGetStaticBody(space)

    def add_statics(self, statics) -> None:
        """Add the walls and obstacles (``(count, vertices)`` polygons) to the static body."""
        for count, verts in statics:
            self._add_shape(self.static, count, verts)

    def add_body(self, body, body_def, x: float, y: float, th: float) -> None:
        """Put ``body`` at its pose in the space with its convex shapes."""
        self.bodies.append(body)
        lib.cpBodySetPosition(body, (x, y))
        lib.cpBodySetAngle(body, th)
        lib.cpSpaceAddBody(self.space, body)
        for count, verts in body_def.parts:
            self._add_shape(body, count, verts)

    def _add_shape(self, body, count: int, verts) -> None:
        shape = lib.cpPolyShapeNew(body, count, verts, _IDENTITY, 0.0)
        self.shapes.append(shape)
        lib.cpShapeSetFriction(shape, self.shape_mu)
        lib.cpSpaceAddShape(self.space, shape)

    def add_constraint(self, constraint) -> None:
        """Add ``constraint`` (its limits already set) to the space."""
        self.constraints.append(constraint)
        lib.cpSpaceAddConstraint(self.space, constraint)

    def free(self) -> None:
        """Free the space, then everything that was added to it."""
        lib.cpSpaceFree(self.space)
        for shape in self.shapes:
            lib.cpShapeFree(shape)
        for constraint in self.constraints:
            lib.cpConstraintFree(constraint)
        for body in self.bodies:
            lib.cpBodyFree(body)


def _moment(rho: float, part_moments) -> float:
    """The moment of a body of density ``rho``: the sum over its convex parts, in order."""
    moment = 0.0
    for area_i, unit_moment in part_moments:
        moment += rho * area_i * unit_moment
    return moment


def _add_movable_bodies(
    scene: _Scene, compiled: _Compiled, state: WorldState, noise: ActionNoise, s: PhysicsSettings
) -> list:
    """Add the bodies of ``state``, in its order, and return them: fixtures clamped
    (kinematic), parts and resting manipulators dynamic at the draw's density with table
    friction (a pivot and a gear joint to the static body with no bias, clipped at the
    Coulomb force and torque)."""
    mu = float(noise.friction)
    g = s.gravity
    static = scene.static
    movable = []
    for obj, (x, y, th) in state.poses:
        body_def = compiled.bodies[obj]
        clamped = body_def.kind is ObjectKind.FIXTURE
        rho = (
            noise.manipulator_density
            if body_def.kind is ObjectKind.MANIPULATOR
            else noise.part_density
        )
        mass = rho * body_def.area
        if clamped:
            # Clamped to the table (see the module docstring): a kinematic body that never
            # moves, with no table friction to model.
            body = lib.cpBodyNewKinematic()
        else:
            body = lib.cpBodyNew(mass, _moment(rho, body_def.part_moments))
        scene.add_body(body, body_def, x, y, th)
        movable.append(body)
        if clamped:
            continue
        pivot = lib.cpPivotJointNew2(static, body, (0.0, 0.0), (0.0, 0.0))
        lib.cpConstraintSetMaxBias(pivot, 0.0)
        lib.cpConstraintSetMaxForce(pivot, mu * mass * g)
        scene.add_constraint(pivot)
        gear = lib.cpGearJointNew(static, body, 0.0, 1.0)
        lib.cpConstraintSetMaxBias(gear, 0.0)
        lib.cpConstraintSetMaxForce(gear, mu * g * rho * body_def.abs_r)
        scene.add_constraint(gear)
    return movable


@dataclass(frozen=True)
class _Paddle:
    """The manipulator of one push as put down: its body, mass and moment (infinite under the
    servo), radius, the (noisy) approach pose and its push direction at that pose."""

    body: object
    mass: float
    moment: float
    radius: float
    pose: Pose
    direction: tuple[float, float]


def _put_down_paddle(
    scene: _Scene, paddle_def, action: Push, noise: ActionNoise, compliant: bool
) -> _Paddle:
    """Add the manipulator at the approach pose plus the draw's offset, with no table friction:
    its own moment under the compliant controller (the wrist can turn), infinite otherwise."""
    ox, oy, oth = noise.pose_offset
    px, py, pth = action.pose
    px, py, pth = float(px) + ox, float(py) + oy, float(pth) + oth
    rho_m = noise.manipulator_density
    mass = rho_m * paddle_def.area
    moment = _moment(rho_m, paddle_def.part_moments) if compliant else math.inf
    body = lib.cpBodyNew(mass, moment)
    scene.add_body(body, paddle_def, px, py, pth)
    direction = rotate(paddle_def.push_direction, pth)
    return _Paddle(body, mass, moment, paddle_def.radius, (px, py, pth), direction)


def _settle(
    scene: _Scene,
    compiled: _Compiled,
    state: WorldState,
    manipulator: str,
    pose: Pose,
    s: PhysicsSettings,
    step,
) -> float:
    """Run ``settle_steps`` undriven steps and return the deepest overlap at the landing: in the
    contacts the engine built, and of the paddle in the geometry (the contacts miss a
    concentric landing); 0 when there are no settle steps."""
    space, dt = scene.space, s.dt
    for _ in range(s.settle_steps):
        step(space, dt)
    if not s.settle_steps:
        return 0.0
    _, landing = compiled.depths.deepest_at(state, manipulator, pose)
    return max(_deepest_overlap(space), landing)


def _start_drive(
    scene: _Scene,
    compiled: _Compiled,
    controller: Controller,
    paddle: _Paddle,
    distance: float,
    s: PhysicsSettings,
    step,
) -> _Servo | _Tracking:
    """The problem's controller driving ``paddle`` ``distance`` along its push direction,
    clipped at the controller's force or the problem's force clip."""
    force = _force_clip(compiled.problem, compiled.parts_area, s)
    if controller.kind is ControllerKind.COMPLIANT:
        if s.compliant_in_solver:
            return _SolverTracking(scene, controller, s, paddle, force, distance, step)
        return _Tracking(controller, s, paddle, force, distance, step)
    return _Servo(scene, controller, s, paddle, force, distance, step)


class _Servo:
    """The servo controller of one push (module docstring): a pivot joint toward the reference
    point, solved with the contacts on pymunk's side."""

    def __init__(
        self,
        scene: _Scene,
        controller: Controller,
        settings: PhysicsSettings,
        paddle: _Paddle,
        force: float,
        distance: float,
        step,
    ) -> None:
        if controller.force is not None:
            force = controller.force
        px, py, _ = paddle.pose
        dx, dy = paddle.direction
        ref = (px + distance * dx, py + distance * dy)
        self.joint = _add_drive(
            scene.space, scene.static, paddle.body, ref, settings, force, controller.speed
        )
        scene.constraints.append(self.joint)
        self.speed = settings.push_speed if controller.speed is None else controller.speed
        self.space = scene.space
        self.dt = settings.dt
        self.step = step
        self.travel_steps = 0  # no set point: still() holds from the first step

    def advance(self, n: int) -> None:
        """Run ``n`` steps (the joint drives the paddle)."""
        step, space, dt = self.step, self.space, self.dt
        for _ in range(n):
            step(space, dt)

    def still(self, tol: float) -> bool:
        """Always: the servo's paddle cannot turn, its position alone is judged."""
        return True

    def stop(self, scene: _Scene) -> None:
        """Stop driving: the joint with no bias holds the paddle where it is."""
        lib.cpConstraintSetMaxBias(self.joint, 0.0)


def _travel_steps(distance: float, speed: float, dt: float) -> int:
    """The last drive step ``k`` at which a set point moving at ``speed`` is short of
    ``distance`` (``k * speed * dt < distance``, as :meth:`_Tracking.still` judges it), 0 when
    it starts at its end."""
    k = max(0, math.ceil(distance / (speed * dt)) - 1)
    if k >= 2**52:  # beyond any cap (a plan file may command 1e300 in); floats step past 1
        return k
    while (k + 1) * speed * dt < distance:
        k += 1
    while k > 0 and k * speed * dt >= distance:
        k -= 1
    return k


class _Tracking:
    """The compliant controller of one push (module docstring): per-axis clipped PD forces and
    a clipped PD torque on the paddle, set before every step toward a set point that moves
    from the approach pose along the push line at ``speed`` and stops ``distance`` along it.

    pymunk clears a body's force and torque after each step, so :meth:`advance` sets them
    before each one.
    """

    def __init__(
        self,
        controller: Controller,
        settings: PhysicsSettings,
        paddle: _Paddle,
        default_force: float,
        distance: float,
        step=lib.cpSpaceStep,
    ) -> None:
        gains = compliant_gains(
            controller, settings, paddle.mass, paddle.moment, paddle.radius, default_force
        )
        self.kp, self.kd = gains.kp, gains.kd
        self.kp_a, self.kd_a = gains.kp_angle, gains.kd_angle
        self.force, self.torque, self.speed = gains.force, gains.torque, gains.speed
        self.space_dt = settings.dt
        self.paddle = paddle.body
        self.start = paddle.pose
        self.direction = paddle.direction
        self.distance = distance
        self.k = 0  # steps driven
        self.last_angle = paddle.pose[2]
        self.step = step
        # Drive steps with the set point short of its end: still() is false until then.
        self.travel_steps = _travel_steps(distance, self.speed, settings.dt)

    def advance(self, n: int) -> None:
        """Run ``n`` steps, setting the controller's force and torque before each."""
        body = self.paddle
        step = self.step
        space = lib.cpBodyGetSpace(body)
        get_pos, get_vel = lib.cpBodyGetPosition, lib.cpBodyGetVelocity
        get_angle, get_w = lib.cpBodyGetAngle, lib.cpBodyGetAngularVelocity
        set_force, set_torque = lib.cpBodySetForce, lib.cpBodySetTorque
        kp, kd, kp_a, kd_a = self.kp, self.kd, self.kp_a, self.kd_a
        fmax, tmax = self.force, self.torque
        x0, y0, th0 = self.start
        ux, uy = self.direction
        dt, reach = self.space_dt, self.speed * self.space_dt
        distance = self.distance
        k = self.k
        for _ in range(n):
            k += 1
            along = min(k * reach, distance)
            pos, vel = get_pos(body), get_vel(body)
            fx = kp * (x0 + along * ux - pos.x) - kd * vel.x
            fy = kp * (y0 + along * uy - pos.y) - kd * vel.y
            tau = kp_a * (th0 - get_angle(body)) - kd_a * get_w(body)
            set_force(body, (min(fmax, max(-fmax, fx)), min(fmax, max(-fmax, fy))))
            set_torque(body, min(tmax, max(-tmax, tau)))
            step(space, dt)
        self.k = k

    def still(self, tol: float) -> bool:
        """Whether the set point has reached its end and the paddle turned less than ``tol``
        since the last call (the caller judges its position)."""
        angle = lib.cpBodyGetAngle(self.paddle)
        turned = abs(angle - self.last_angle)
        self.last_angle = angle
        return self.k * self.speed * self.space_dt >= self.distance and turned < tol

    def stop(self, scene: _Scene) -> None:
        """Stop driving: hold the paddle where it is (pivot and gear with no bias, clipped at
        the force and torque clips) while the other bodies come to rest."""
        pivot = lib.cpPivotJointNew(scene.static, self.paddle, lib.cpBodyGetPosition(self.paddle))
        lib.cpConstraintSetMaxBias(pivot, 0.0)
        lib.cpConstraintSetMaxForce(pivot, self.force)
        lib.cpSpaceAddConstraint(scene.space, pivot)
        gear = lib.cpGearJointNew(scene.static, self.paddle, 0.0, 1.0)
        lib.cpConstraintSetMaxBias(gear, 0.0)
        lib.cpConstraintSetMaxForce(gear, self.torque)
        lib.cpSpaceAddConstraint(scene.space, gear)
        scene.constraints.extend((pivot, gear))


#: Length (in) of the springs and dampers of :class:`_SolverTracking`, each anchored this far
#: behind the paddle along its axis: so long that a sideways offset of tens of inches changes
#: its length by less than 1e-4 in and turns its line by less than 1e-4 rad, so that each acts
#: along one axis only.
_AXIS_SPRING_LENGTH = 1.0e6


def _lag_matched_damping(kd: float, inertia: float, dt: float) -> float:
    """The engine's damping coefficient that gives a paddle of ``inertia`` (mass or moment)
    tracking a set point moving at constant speed the explicit PD's lag, ``Kd v / Kp``: the
    engine damps implicitly (velocity times ``exp(-c dt / m)`` per step), which at the same
    ``Kd`` lags by ``1 + Kd dt / 2m`` times more; ``c = m / dt * log(1 + Kd dt / m)`` (chosen
    on ``benchmarks/push_accuracy.py``, ``docs/design/physics-controller.md``)."""
    return inertia / dt * math.log1p(kd * dt / inertia)


class _SolverTracking(_Tracking):
    """The compliant controller of one push solved by the engine: the same PD, set point and
    clips as :class:`_Tracking`, built from constraints so that no Python runs per step.

    A kinematic *set-point body* starts at the paddle's approach pose and moves along the push
    line at ``speed``, stopping ``distance`` along it. Per world axis, a damped spring of
    stiffness ``Kp`` and no damping joins it to the paddle's centroid (the PD's proportional
    term) and a damper of ``Kd`` and no stiffness joins the static body to the centroid (its
    derivative term, on the paddle's own velocity as the PD's is); each is
    ``_AXIS_SPRING_LENGTH`` long along its axis, so it acts along that axis alone. A rotary
    spring of ``Kp_angle`` and ``Kd_angle`` joins the set-point body (never turning) to the
    paddle. The engine applies the springs' forces explicitly, like the force set before a
    step, and the dampers implicitly, their coefficients chosen so that a paddle tracking the
    moving set point lags it as the PD's does (:func:`_lag_matched_damping`). Selected by
    :attr:`PhysicsSettings.compliant_in_solver`.

    The clips are applied between chunks of steps (:meth:`_clip`): an axis whose
    spring force exceeds the force clip (the torque clip) has its rest length (rest angle)
    shifted so that it pulls with the clip, until its error falls back within it.
    """

    def __init__(
        self,
        scene: _Scene,
        controller: Controller,
        settings: PhysicsSettings,
        paddle: _Paddle,
        default_force: float,
        distance: float,
        step=lib.cpSpaceStep,
    ) -> None:
        super().__init__(controller, settings, paddle, default_force, distance, step)
        self.space = scene.space
        x0, y0, th0 = paddle.pose
        ux, uy = self.direction
        length = _AXIS_SPRING_LENGTH
        setpoint = lib.cpBodyNewKinematic()
        scene.bodies.append(setpoint)
        lib.cpBodySetPosition(setpoint, (x0, y0))  # unturned: its anchors are world axes
        lib.cpSpaceAddBody(scene.space, setpoint)
        self.setpoint = setpoint
        # The engine moves the set point from step 1 to step travel_steps; advance() puts it
        # at its end before the next.
        if self.travel_steps > 0:
            lib.cpBodySetVelocity(setpoint, (self.speed * ux, self.speed * uy))
        self.interval = settings.interval_steps
        self.end = (x0 + distance * ux, y0 + distance * uy)
        self.springs = []
        self.drive = []
        for ax, ay in ((1.0, 0.0), (0.0, 1.0)):
            spring = lib.cpDampedSpringNew(
                setpoint, paddle.body, (-length * ax, -length * ay), (0.0, 0.0), length, self.kp, 0
            )
            damper = lib.cpDampedSpringNew(
                scene.static,
                paddle.body,
                (x0 - length * ax, y0 - length * ay),
                (0.0, 0.0),
                length,
                0.0,
                _lag_matched_damping(self.kd, paddle.mass, settings.dt),
            )
            self.springs.append(spring)
            self.drive += [spring, damper]
        kd_angle = _lag_matched_damping(self.kd_a, paddle.moment, settings.dt)
        self.rotary = lib.cpDampedRotarySpringNew(setpoint, paddle.body, -th0, self.kp_a, kd_angle)
        self.drive.append(self.rotary)
        for constraint in self.drive:
            scene.add_constraint(constraint)
        self.clipped = [False, False, False]

    def _clip(self) -> int:
        """Shift the rest length (angle) of each spring pulling harder than its clip so that it
        pulls with the clip, restore those back within it, and return how many steps may pass
        before the next call: while the set point moves, until it could bring a linear error
        to the clip (the paddle moving back as fast), at least ``interval``; else 1 (the
        caller's chunk)."""
        body, clipped = self.paddle, self.clipped
        pos = lib.cpBodyGetPosition(body)
        target = lib.cpBodyGetPosition(self.setpoint)
        length = _AXIS_SPRING_LENGTH
        limit = self.force / self.kp
        largest = 0.0
        for axis, error in enumerate((target.x - pos.x, target.y - pos.y)):
            largest = max(largest, abs(error))
            if abs(error) > limit:
                held = limit if error > 0.0 else -limit
                lib.cpDampedSpringSetRestLength(self.springs[axis], length + held - error)
                clipped[axis] = True
            elif clipped[axis]:
                lib.cpDampedSpringSetRestLength(self.springs[axis], length)
                clipped[axis] = False
        error = self.start[2] - lib.cpBodyGetAngle(body)
        if abs(error) * self.kp_a > self.torque:
            held = self.torque / self.kp_a
            lib.cpDampedRotarySpringSetRestAngle(
                self.rotary, error - (held if error > 0.0 else -held) - self.start[2]
            )
            clipped[2] = True
        elif clipped[2]:
            lib.cpDampedRotarySpringSetRestAngle(self.rotary, -self.start[2])
            clipped[2] = False
        if self.k >= self.travel_steps:
            return 1
        reach = self.speed * self.space_dt
        return max(self.interval, int((limit - largest) / (2.0 * reach)))

    def advance(self, n: int) -> None:
        """Run ``n`` steps, clipping between chunks (:meth:`_clip`) and putting the set point
        at its end before the step at which it gets there."""
        step, space, dt = self.step, self.space, self.space_dt
        travel = self.travel_steps
        while n > 0:
            chunk = min(n, self._clip())
            k = self.k
            if k < travel < k + chunk:
                chunk = travel - k
            if k == travel:
                lib.cpBodySetVelocity(self.setpoint, (0.0, 0.0))
                lib.cpBodySetPosition(self.setpoint, self.end)
            for _ in range(chunk):
                step(space, dt)
            self.k = k + chunk
            n -= chunk

    def stop(self, scene: _Scene) -> None:
        """Stop driving: remove the springs and dampers, then hold the paddle (the brake of
        :meth:`_Tracking.stop`)."""
        for constraint in self.drive:
            lib.cpSpaceRemoveConstraint(scene.space, constraint)
        super().stop(scene)


class _PushRun:
    """The stepping of one push after the settle, in rest checks every ``interval`` steps
    (module docstring, "Rest"): :meth:`drive_until_still`, then :meth:`hold_until_rest`.

    The whole push is capped at :meth:`PhysicsSettings.cap_steps` for the travel across the
    table at most (a push commanded further, which a plan file may say, ends against a wall or
    off the table by then); a push not at rest ``stuck_time`` after its set point's end gets
    ``stuck_iterations`` from then on, and its drive also ends once the paddle's progress along
    the push over the last ``stall_window`` is below the rest speed (chatter is not motion).
    After the run, ``steps`` counts every step taken (the settle's included), ``capped`` says
    whether the cap was hit and ``travel`` is how far the paddle moved along its push direction
    while it was driven.
    """

    def __init__(
        self,
        scene: _Scene,
        compiled: _Compiled,
        paddle: _Paddle,
        drive: _Servo | _Tracking,
        movable: list,
        distance: float,
        s: PhysicsSettings,
        step,
        watch: Callable[[list], None] | None,
    ) -> None:
        self.scene = scene
        self.paddle = paddle
        self.drive = drive
        self.s = s
        self.step = step
        self.watch = watch
        self.interval = s.interval_steps
        setpoint_end = distance / drive.speed
        crossing = push_crossing(compiled.table.size, paddle.radius)
        self.max_steps = s.cap_steps(min(distance, crossing) / drive.speed)
        if s.stuck_time > 0.0:
            self.stuck_at = math.ceil((setpoint_end + s.stuck_time) / s.dt)
        else:
            self.stuck_at = self.max_steps + 1
        self.stuck = False
        self.steps = s.settle_steps
        self.capped = False
        self.travel = 0.0
        self.rest = _RestCount(movable, s.rest_linear_tol, s.rest_angular_tol)

    def _escalate_when_stuck(self) -> None:
        """From ``stuck_at`` on, solve with ``stuck_iterations`` (once)."""
        if self.steps >= self.stuck_at:
            lib.cpSpaceSetIterations(self.scene.space, self.s.stuck_iterations)
            self.stuck_at = self.max_steps + 1
            self.stuck = True

    def _hold(self, n: int) -> None:
        step, space, dt = self.step, self.scene.space, self.s.dt
        for _ in range(n):
            step(space, dt)

    def drive_until_still(self) -> bool:
        """Drive the paddle until it was still ``rest_checks`` checks in a row (position and,
        compliant, angle, with its set point at its end) or stalled, then stop driving (the
        drive becomes a brake); return whether that happened before the cap. The other bodies
        are watched from the first check at which the paddle is still, so that the check that
        stops the drive can count toward their rest."""
        s, drive, interval = self.s, self.drive, self.interval
        need = s.rest_checks
        lin2 = s.rest_linear_tol * s.rest_linear_tol
        ang_tol = s.rest_angular_tol
        body = self.paddle.body
        px, py, _ = self.paddle.pose
        dx, dy = self.paddle.direction
        window = round(s.stall_window / (interval * s.dt)) if s.stall_window > 0.0 else 0
        window_progress = s.rest_linear_tol * window
        progress: deque[float] = deque(maxlen=window + 1)
        rest = self.rest
        paddle_still = 0
        last_x, last_y = px, py
        # The checks before the set point's end cannot find the paddle still: step over them
        # at once (the last one only records the paddle's position).
        skip = drive.travel_steps // interval * interval
        if skip and self.steps + skip <= self.max_steps:
            drive.advance(skip)
            self.steps += skip
            pos = lib.cpBodyGetPosition(body)
            last_x, last_y = pos.x, pos.y
            drive.still(ang_tol)  # records the angle, as every check does
        while True:
            self._escalate_when_stuck()
            if self.steps + interval > self.max_steps:
                drive.advance(self.max_steps - self.steps)
                self.steps = max(self.steps, self.max_steps)
                self.capped = True
                pos = lib.cpBodyGetPosition(body)
                self.travel = (pos.x - px) * dx + (pos.y - py) * dy
                return False
            drive.advance(interval)
            self.steps += interval
            pos = lib.cpBodyGetPosition(body)
            ex, ey = pos.x - last_x, pos.y - last_y
            last_x, last_y = pos.x, pos.y
            # The compliant paddle must also have stopped turning, its set point at its end.
            done = drive.still(ang_tol)
            if self.stuck and window:
                progress.append(pos.x * dx + pos.y * dy)
            if len(progress) > window and abs(progress[-1] - progress[0]) < window_progress:
                paddle_still = need  # stalled: the drive ends below
            elif ex * ex + ey * ey < lin2 and done:
                paddle_still += 1
            else:
                paddle_still = 0
                rest.reset()
                continue
            rest.check()
            if paddle_still >= need:
                drive.stop(self.scene)
                self.travel = (last_x - px) * dx + (last_y - py) * dy
                if self.watch is not None:
                    self.watch(None)  # the drive's end
                return True

    def hold_until_rest(self) -> None:
        """With the paddle held, step until every other body was still ``rest_checks`` checks
        in a row (counting from :meth:`drive_until_still`), or the cap."""
        interval, need, rest = self.interval, self.s.rest_checks, self.rest
        while True:
            self._escalate_when_stuck()
            if self.steps + interval > self.max_steps:
                self._hold(self.max_steps - self.steps)
                self.steps = max(self.steps, self.max_steps)
                self.capped = True
                return
            self._hold(interval)
            self.steps += interval
            rest.check()
            if rest.still >= need:
                return


class _RestCount:
    """How many rest checks in a row ``bodies`` were all still: each moved less than
    ``linear_tol`` and turned less than ``angular_tol`` since the previous check (the first
    check after a reset only records the poses)."""

    def __init__(self, bodies: list, linear_tol: float, angular_tol: float) -> None:
        self.bodies = bodies
        self.lin2 = linear_tol * linear_tol
        self.ang_tol = angular_tol
        self.last: list | None = None
        self.still = 0

    def reset(self) -> None:
        """Forget the poses and the count."""
        self.last = None
        self.still = 0

    def check(self) -> None:
        """Compare the bodies' poses with the previous check's and count."""
        get_pos, get_angle = lib.cpBodyGetPosition, lib.cpBodyGetAngle
        now = []
        for b in self.bodies:
            pos = get_pos(b)
            now.append((pos.x, pos.y, get_angle(b)))
        last = self.last
        if last is not None:
            lin2, ang_tol = self.lin2, self.ang_tol
            for (x0, y0, a0), (x1, y1, a1) in zip(last, now, strict=True):
                if (x1 - x0) ** 2 + (y1 - y0) ** 2 >= lin2 or abs(a1 - a0) >= ang_tol:
                    self.still = 0
                    break
            else:
                self.still += 1
        self.last = now


@dataclass(frozen=True)
class CompliantGains:
    """The compliant controller's gains and clips for one paddle, resolved
    (:func:`compliant_gains`)."""

    kp: float
    """Proportional gain per axis (force per inch of tracking error)."""
    kd: float
    """Derivative gain per axis: ``damping_ratio * sqrt(4 m Kp)``."""
    kp_angle: float
    """Proportional gain on the angle (torque per radian)."""
    kd_angle: float
    """Derivative gain on the angle: ``damping_ratio * sqrt(4 I Kp_angle)``."""
    force: float
    """Clip of the force on each axis."""
    torque: float
    """Clip of the torque."""
    speed: float
    """Speed of the set point along the push line (in/s)."""


def compliant_gains(
    controller: Controller,
    settings: PhysicsSettings,
    mass: float,
    moment: float,
    radius: float,
    default_force: float,
) -> CompliantGains:
    """The gains and clips of the compliant controller for a paddle of ``mass``, ``moment`` and
    ``radius`` (the largest distance of its outline from its centroid), the ``None`` fields of
    ``controller`` at their defaults (:class:`~arrange_up.model.problem.Controller`), the force
    clip at ``default_force``: ``Kp_angle = Kp radius^2``, so that a force at the paddle's end
    moves that end about as far by turning it as a force at its centre moves the centre (a
    wrist as stiff as the arm), and ``torque = force * radius``; ``Kd = damping_ratio *
    sqrt(4 m Kp)`` and likewise on the angle."""
    kp = controller.kp
    kp_a = kp * radius * radius if controller.kp_angle is None else controller.kp_angle
    force = default_force if controller.force is None else controller.force
    torque = force * radius if controller.torque is None else controller.torque
    speed = settings.push_speed if controller.speed is None else controller.speed
    zeta = settings.damping_ratio
    kd = zeta * math.sqrt(4.0 * mass * kp)
    kd_a = zeta * math.sqrt(4.0 * moment * kp_a)
    return CompliantGains(kp, kd, kp_a, kd_a, force, torque, speed)


#: The largest ``sqrt(K / m) * dt`` (and ``sqrt(K_angle / I) * dt``) at which the compliant
#: controller's explicitly integrated PD follows its set point (docs/problem-format-planner.md,
#: ``controller:``); beyond it the simulated paddle oscillates and parts are thrown.
STABLE_RATE = 0.5


class StiffManipulator(NamedTuple):
    """A manipulator the compliant controller is too stiff for (:func:`stiff_manipulators`)."""

    name: str
    rate: float
    """The larger of ``sqrt(Kp / m) dt`` and ``sqrt(Kp_angle / I) dt``."""
    kp_max: float
    """The largest value of :attr:`gain` (internal units) that keeps the rate at
    :data:`STABLE_RATE`."""
    gain: str = "kp"
    """The gain too stiff: ``kp``, or ``kp_angle`` when an explicit angle gain is."""


def stiff_manipulators(
    problem: ArrangementProblem, settings: PhysicsSettings = DEFAULT_SETTINGS
) -> list[StiffManipulator]:
    """The manipulators the problem's compliant controller is too stiff for at the time step,
    as :class:`StiffManipulator` ``(name, rate, kp_max)``: ``rate`` the larger of
    ``sqrt(Kp / m) dt`` and ``sqrt(Kp_angle / I) dt`` at the lightest manipulator density,
    above :data:`STABLE_RATE`, and ``kp_max`` the largest ``kp`` (internal units) that keeps
    both at it when the angle gain is its default ``kp r^2`` (with an explicit ``kp_angle``,
    the linear bound alone). Empty under the servo."""
    controller = problem.controller
    if controller.kind is not ControllerKind.COMPLIANT:
        return []
    compiled = _compile(problem, settings.wall_thickness)
    rho = problem.uncertainty.manipulator_density[0]
    force = _force_clip(problem, compiled.parts_area, settings)
    found = []
    for spec in problem.manipulators:
        body = compiled.bodies[spec.name]
        mass = rho * body.area
        moment = sum(rho * area * unit for area, unit in body.part_moments)
        gains = compliant_gains(controller, settings, mass, moment, body.radius, force)
        kp, kp_a = gains.kp, gains.kp_angle
        dt = settings.dt
        linear, angular = math.sqrt(kp / mass) * dt, math.sqrt(kp_a / moment) * dt
        rate = max(linear, angular)
        if rate > STABLE_RATE:
            if controller.kp_angle is not None and angular > max(linear, STABLE_RATE):
                # the explicit angle gain is what is too stiff: lowering kp would not help
                limit = moment * (STABLE_RATE / dt) ** 2
                found.append(StiffManipulator(spec.name, rate, limit, "kp_angle"))
                continue
            limit = mass * (STABLE_RATE / dt) ** 2
            if controller.kp_angle is None:
                limit = min(limit, moment / body.radius**2 * (STABLE_RATE / dt) ** 2)
            found.append(StiffManipulator(spec.name, rate, limit))
    return found


def _watched_step(watch: Callable[[list], None], bodies: list):
    """``cpSpaceStep`` followed by ``watch([(x, y, angle, vx, vy, w), ...])`` of ``bodies``
    (the movable bodies in state order, then the paddle): for measurements only."""
    step = lib.cpSpaceStep

    def watched(space, dt: float) -> None:
        step(space, dt)
        out = []
        for b in bodies:
            p, v = lib.cpBodyGetPosition(b), lib.cpBodyGetVelocity(b)
            out.append((p.x, p.y, lib.cpBodyGetAngle(b), v.x, v.y, lib.cpBodyGetAngularVelocity(b)))
        watch(out)

    return watched


def simulate_watched(
    problem: ArrangementProblem,
    state: WorldState,
    action: Push,
    watch: Callable[[list | None], None],
    noise: ActionNoise | None = None,
    settings: PhysicsSettings = DEFAULT_SETTINGS,
) -> StepOutcome:
    """:func:`simulate` of a push, calling ``watch`` after every step with the pose and
    velocity ``(x, y, angle, vx, vy, w)`` of every movable body in state order and then of the
    manipulator (once with ``None`` when the drive ends). The same outcome as
    :func:`simulate`, slower; for the controller's measurements (``benchmarks/controller.py``).
    """
    compiled = _compile(problem, settings.wall_thickness)
    _check_state(compiled, state)
    return _push(compiled, state, action, noise or nominal_noise(problem), settings, watch=watch)


def _check_noise(noise: ActionNoise) -> None:
    if not (math.isfinite(noise.friction) and noise.friction >= 0.0):
        raise ValueError(f"friction must be finite and non-negative, got {noise.friction!r}")
    for name in ("part_density", "manipulator_density"):
        value = getattr(noise, name)
        if not (math.isfinite(value) and value > 0.0):
            raise ValueError(f"{name} must be positive and finite, got {value!r}")


def _deepest_overlap(space) -> float:
    """Deepest penetration (in, >= 0) among the contacts of the last step."""
    floats = lib.pmFloatArrayNew(0)
    ints = lib.pmIntArrayNew(0)
    try:
        data = ffi.new("pmBatchedData *")
        data.fields = lib.DISTANCE_1 | lib.DISTANCE_2 | lib.CONTACT_COUNT
        data.floatArray = floats
        data.intArray = ints
        lib.cpSpaceEachCachedArbiter(
            space, ffi.addressof(lib, "pmSpaceArbiterIteratorFuncBatched"), data
        )
        n = floats.num
        if n == 0:
            return 0.0
        deepest = min(floats.arr[i] for i in range(n))
        return max(0.0, -float(deepest))
    finally:
        lib.pmFloatArrayFree(floats)
        lib.pmIntArrayFree(ints)


def _drive_trajectory(
    mass: float,
    start: tuple[float, float],
    ref: tuple[float, float],
    n_steps: int,
    settings: PhysicsSettings = DEFAULT_SETTINGS,
) -> list[tuple[float, float, float, float]]:
    """``(x, y, vx, vy)`` after each step of a lone paddle driven toward ``ref``.

    The paddle (``mass``, infinite moment, no shape) is driven by exactly the joint
    :func:`simulate` uses (:func:`_add_drive`); the tests compare this with the clipped PD it
    implements.
    """
    settings = settings.for_controller(ControllerKind.SERVO)
    space = lib.cpSpaceNew()
    paddle = lib.cpBodyNew(mass, math.inf)
    drive = None
    try:
        lib.cpSpaceSetIterations(space, settings.iterations)
        lib.cpBodySetPosition(paddle, start)
        lib.cpSpaceAddBody(space, paddle)
        drive = _add_drive(
            space, lib.cpSpaceGetStaticBody(space), paddle, ref, settings, settings.push_force
        )
        out = []
        for _ in range(n_steps):
            lib.cpSpaceStep(space, settings.dt)
            p = lib.cpBodyGetPosition(paddle)
            v = lib.cpBodyGetVelocity(paddle)
            out.append((p.x, p.y, v.x, v.y))
        return out
    finally:
        lib.cpSpaceFree(space)
        if drive is not None:
            lib.cpConstraintFree(drive)
        lib.cpBodyFree(paddle)
