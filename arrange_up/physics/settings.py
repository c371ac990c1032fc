"""The settings of the simulation (:class:`PhysicsSettings`, :data:`DEFAULT_SETTINGS`) and the
controller's force clip and gains derived from them. The model they parameterise is described
in :mod:`arrange_up.physics.simulation`."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from arrange_up.model.problem import STANDARD_GRAVITY, ArrangementProblem, ControllerKind

__all__ = [
    "COMPLIANT_VALUES",
    "CONTROLLER_VALUES",
    "DEFAULT_SETTINGS",
    "SERVO_VALUES",
    "PhysicsSettings",
    "pd_gains",
    "push_crossing",
    "push_force",
]


@dataclass(frozen=True)
class PhysicsSettings:
    """Numerical and controller settings of the simulation (inches, seconds, radians).

    The settling and rest fields (``iterations``, ``rest_*``, ``sleep_time``) default to
    ``None``: a push takes its controller's values (:meth:`for_controller`,
    :data:`CONTROLLER_VALUES`); a value given explicitly holds for both controllers. Every
    default is argued in :mod:`arrange_up.physics.simulation` or measured in
    ``docs/design/physics.md`` and ``docs/design/physics-controller.md``.
    """

    dt: float = 1.0 / 240.0
    """Time step. 1/60 is too coarse for chains of blocks (see ``docs/design/physics.md``)."""
    iterations: int | None = None
    """Solver iterations per step; ``None``: the controller's (:data:`CONTROLLER_VALUES`; the
    servo 10, the safe end of the accurate range at dt 1/240; the compliant controller 5)."""
    collision_slop: float = 0.005
    """Allowed resting overlap (in). pymunk's default 0.1 is sized for pixels."""
    collision_bias: float = 0.8**240
    """Fraction of an overlap beyond the slop left uncorrected after one second: ``0.8 ** 240``
    corrects 20% per step at dt 1/240 (Box2D's Baumgarte factor; pymunk's default ``0.9 ** 60``
    is 2.6% per step and lets squeezed chains creep for a second, see
    :mod:`arrange_up.physics.simulation`)."""
    gravity: float = STANDARD_GRAVITY
    """Standard gravity in in/s^2; only the table friction uses it (the world is top-down)."""
    rest_interval: float | None = None
    """Simulated time between rest checks (s), rounded to whole steps; ``None``: the
    controller's (:data:`CONTROLLER_VALUES`; the servo 0.1 s, 24 steps at dt 1/240; the
    compliant controller 0.0125 s, 3 steps)."""
    rest_linear_tol: float | None = None
    """A body is still when it moved less than this (in) since the previous check...
    (``None``: the controller's, the servo 1e-3, the compliant controller 1.25e-4: both
    0.01 in/s at their intervals)"""
    rest_angular_tol: float | None = None
    """...and turned less than this (rad) (``None``: the controller's, the servo 1e-3, the
    compliant controller 1.25e-4)."""
    rest_checks: int | None = None
    """Consecutive still checks that make rest (one can be a momentary stop); ``None``: the
    controller's (2 for both)."""
    sleep_time: float | None = None
    """Bodies idle (slower than ``rest_linear_tol / rest_interval``) for this long (s) sleep:
    the engine stops solving them and their joints until something touches them; 0 turns
    sleeping off. ``None``: the controller's (the servo 0, the compliant controller 0.05;
    :data:`CONTROLLER_VALUES`)."""
    stuck_time: float | None = None
    """Simulated time (s) after the set point's end at which a push that has not come to rest
    gets ``stuck_iterations`` solver iterations for the rest of it; 0 turns this off.
    ``None``: the controller's (the servo 0, the compliant controller 1.0). A compliant paddle
    that has turned and presses a tilted part into a wall or post wedges it, and at 5 (or 10)
    iterations the solver makes that wedge chatter (the paddle oscillating by about 0.03 in)
    until the cap; with more iterations it settles (``docs/design/physics.md``)."""
    stuck_iterations: int | None = None
    """Solver iterations per step once ``stuck_time`` has passed (``None``: the controller's,
    20 for both)."""
    stall_window: float | None = None
    """Once ``stuck_time`` has passed, the drive also ends when the paddle has advanced along
    its push by less than the rest speed (``rest_linear_tol`` per ``rest_interval``) on
    average over the last ``stall_window`` seconds: a stalled paddle whose wedge still chatters
    (back and forth, or creeping sideways along a wall), which the check-to-check rest test
    reads as motion, so the drive ran to the cap. 0 turns this off; ``None``: the
    controller's (the servo 0, the compliant controller 0.5; ``docs/design/physics.md``)."""
    max_time: float = 20.0
    """Cap on the simulated time of one push (s); hitting it gives ``NOT_AT_REST``. A push
    whose set point reaches its end later than ``max_time - travel_margin`` at the push speed
    is capped ``travel_margin`` after that end instead (:meth:`cap_steps`)."""
    travel_margin: float = 10.0
    """Simulated time (s) a long push gets after its set point's end (a set point ending after
    ``max_time - travel_margin``, about 30 in at the default speed): a push beyond about 60 in
    (a metre-scale problem's) could not arrive within ``max_time`` and ended ``NOT_AT_REST``
    whatever happened; shorter pushes keep the ``max_time`` cap."""
    settle_steps: int = 2
    """Steps run after writing the state, before driving the manipulator: the thesis ran "a
    couple of time steps" so the engine builds its contact state first. The overlap check reads
    the contacts they build and the manipulator's landing geometry (0 turns the check off)."""
    push_speed: float = 3.0
    """Speed limit of the manipulator (in/s): a careful robot push, 0.0125 in per step."""
    push_force: float = 400.0
    """Force clip of the controller (mass-in/s^2, mass = density x in^2): pushes a 7-block
    chain at the worst friction and density of the thesis's ranges (223) with margin. A
    problem whose parts are heavier raises it (see :func:`push_force`)."""
    load_margin: float = 1.5
    """The clip is at least this many times the friction of all the problem's parts at the
    middle of its friction and part-density ranges (:func:`push_force`)."""
    damping_ratio: float = 1.0
    """Damping ratio of the PD; 1 is the thesis's critically damped Kd = sqrt(4 m Kp)."""
    wall_thickness: float = 1.0
    """Thickness of the static wall boxes (in); far more than one step's travel."""
    overlap_tolerance: float = 0.02
    """Deepest overlap between shapes (in) accepted when the push starts; deeper gives
    ``OVERLAP`` (overlapping bodies drift apart for seconds and the result means little)."""
    compliant_in_solver: bool = False
    """Run the compliant controller inside the engine's solver (springs and dampers on a
    set-point body, :mod:`arrange_up.physics.simulation`) rather than as a force set from
    Python before every step. The choice and its measurements:
    ``docs/design/physics-controller.md``."""

    def __post_init__(self) -> None:
        positive = (
            "dt",
            "gravity",
            "rest_interval",
            "max_time",
            "travel_margin",
            "push_speed",
            "push_force",
            "load_margin",
            "damping_ratio",
            "wall_thickness",
            "collision_slop",
        )
        for name in positive:
            value = getattr(self, name)
            if value is None and name in CONTROLLER_VALUES[ControllerKind.SERVO]:
                continue
            if not (math.isfinite(value) and value > 0):
                raise ValueError(
                    f"PhysicsSettings.{name} must be positive and finite, got {value!r}"
                )
        for name in (
            "rest_linear_tol",
            "rest_angular_tol",
            "overlap_tolerance",
            "sleep_time",
            "stuck_time",
            "stall_window",
        ):
            value = getattr(self, name)
            if value is not None and not value >= 0:
                raise ValueError(f"PhysicsSettings.{name} must be non-negative")
        for name in ("iterations", "rest_checks", "stuck_iterations"):
            value = getattr(self, name)
            if value is not None and value < 1:
                raise ValueError(f"PhysicsSettings.{name} must be at least 1")
        if not 0.0 <= self.collision_bias <= 1.0:
            raise ValueError("PhysicsSettings.collision_bias must be in [0, 1]")
        if self.settle_steps < 0:
            raise ValueError("PhysicsSettings.settle_steps must be non-negative")
        if self.approach_rate * self.dt > 1.0:
            raise ValueError(
                "PhysicsSettings.damping_ratio must be at least 0.5 (a smaller "
                "one makes the discrete controller overshoot)"
            )

    @property
    def approach_rate(self) -> float:
        """Rate (1/s) of the position loop, ``Kp / Kd = 1 / (4 damping_ratio^2 dt)``."""
        return 1.0 / (4.0 * self.damping_ratio * self.damping_ratio * self.dt)

    def for_controller(self, kind: ControllerKind) -> PhysicsSettings:
        """These settings with every ``None`` field at the value of controller ``kind``
        (:data:`CONTROLLER_VALUES`); fields given explicitly hold for every controller."""
        values = CONTROLLER_VALUES[kind]
        return replace(self, **{k: v for k, v in values.items() if getattr(self, k) is None})

    @property
    def interval_steps(self) -> int:
        """Steps between rest checks (of settings resolved by :meth:`for_controller`)."""
        if self.rest_interval is None:
            raise ValueError("PhysicsSettings.rest_interval is None: resolve with for_controller")
        return max(1, round(self.rest_interval / self.dt))

    @property
    def max_steps(self) -> int:
        """Steps in ``max_time`` (the cap of a push that arrives in time)."""
        return max(1, math.ceil(self.max_time / self.dt - 1e-9))

    def cap_steps(self, setpoint_end: float) -> int:
        """Steps a push may run whose set point reaches its end after ``setpoint_end`` seconds
        (the simulation passes the time to cross the table at most): :attr:`max_steps`, or
        ``travel_margin`` after that end when it is later."""
        return max(self.max_steps, math.ceil((setpoint_end + self.travel_margin) / self.dt))


SERVO_VALUES: dict[str, float | int] = {
    "iterations": 10,
    "rest_interval": 0.1,
    "rest_linear_tol": 1e-3,
    "rest_angular_tol": 1e-3,
    "rest_checks": 2,
    "sleep_time": 0.0,
    "stuck_time": 0.0,
    "stuck_iterations": 20,
    "stall_window": 0.0,
}
"""The servo's settling and rest settings: those every push used before they were chosen
per controller. The servo keeps them, so that its plans, goldens and measurements stay
reproducible bit for bit (``docs/design/physics.md``); so it never raises its solver
iterations for a push that is slow to rest."""

COMPLIANT_VALUES: dict[str, float | int] = {
    "iterations": 5,
    "rest_interval": 0.0125,
    "rest_linear_tol": 1.25e-4,
    "rest_angular_tol": 1.25e-4,
    "rest_checks": 2,
    "sleep_time": 0.05,
    "stuck_time": 1.0,
    "stuck_iterations": 20,
    "stall_window": 0.5,
}
"""The compliant controller's settling and rest settings, chosen on the accuracy benchmark
(``benchmarks/push_accuracy.py``; the alternatives measured are in ``docs/design/physics.md``):
a check every 3 steps (0.0125 s) with the old speed threshold (1.25e-4 in per check is the old
1e-3 in per 0.1 s, 0.01 in/s), 5 solver iterations, and bodies idle for 0.05 s asleep; a push
not at rest 1 s after its set point's end is solved at 20 iterations from then on, and its
drive ends once the paddle has made no progress along the push for 0.5 s. Fewer steps and
less time than the servo's values, final poses as close to the reference (the figures:
``docs/design/physics.md``, "Settling and rest per controller")."""

CONTROLLER_VALUES: dict[ControllerKind, dict[str, float | int]] = {
    ControllerKind.SERVO: SERVO_VALUES,
    ControllerKind.COMPLIANT: COMPLIANT_VALUES,
}
"""controller kind -> the values :meth:`PhysicsSettings.for_controller` gives the ``None``
fields."""

DEFAULT_SETTINGS = PhysicsSettings()
"""The defaults: the settling and rest fields ``None``, so that each push takes its
controller's (:data:`CONTROLLER_VALUES`)."""


def push_crossing(table_size: tuple[float, float], radius: float) -> float:
    """The longest travel a push can make on a table of ``table_size`` with a manipulator of
    ``radius`` before it ends against a wall or off the table (inches): the diagonal, plus the
    manipulator on either side. The long-push cap makes room for this much at most
    (:meth:`PhysicsSettings.cap_steps`)."""
    return math.hypot(*table_size) + 2.0 * radius


def push_force(problem: ArrangementProblem, settings: PhysicsSettings = DEFAULT_SETTINGS) -> float:
    """The controller's force clip for ``problem``: ``settings.push_force``, raised to
    ``load_margin`` times the table friction of every part of the problem at the middle of its
    friction and part-density ranges when that is more.

    Densities are in the problem's own mass units, so a fixed clip cannot suit every problem:
    the thesis's noisy TT mating draws densities up to 1.0, eight times the blocks', and a clip
    sized for blocks could not move its parts at all under nominal parameters. Scaled this way
    the robot always pushes everything the problem has at once under nominal parameters, with
    margin, while the heaviest, most frictional draws of a very noisy problem may still stall
    it, as the thesis's low-gain controller stalled ("doesn't apply enough force to move the
    desired distance when there are collisions", §2.1.3). Every shipped problem but the noisy
    TT mating keeps the default (the largest nominal load, TT mating's, needs 398).
    """
    return _force_clip(problem, sum(spec.shape.area for spec in problem.parts), settings)


def _force_clip(problem: ArrangementProblem, parts_area: float, settings: PhysicsSettings) -> float:
    u = problem.uncertainty
    friction = 0.5 * (u.friction[0] + u.friction[1])
    density = 0.5 * (u.part_density[0] + u.part_density[1])
    # Keep this product's order: simulations are chaotic to the last bit, and reassociating it
    # changed four of tt-mating-noisy's five nominal plans (and staled their measurements).
    return max(
        settings.push_force,
        settings.load_margin * settings.gravity * friction * density * parts_area,
    )


def pd_gains(mass: float, settings: PhysicsSettings = DEFAULT_SETTINGS) -> tuple[float, float]:
    """``(Kp, Kd)`` of the PD the push controller is, for a paddle of ``mass`` (free motion).

    ``Kd = m / dt`` (dead-beat velocity loop) and ``Kp = approach_rate * Kd``; with the default
    ``damping_ratio = 1`` that is ``Kd = sqrt(4 m Kp)``.
    """
    kd = mass / settings.dt
    return settings.approach_rate * kd, kd
