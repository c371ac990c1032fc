"""The physics settings chosen per controller (``PhysicsSettings.for_controller``) and body
sleeping: the servo keeps the settings every push had before, bit for bit; explicit values
hold for both controllers."""

from __future__ import annotations

import dataclasses
import math

import pytest

from arrange_up.model.problem import (
    SERVO_CONTROLLER,
    ArrangementProblem,
    ControllerKind,
    Goal,
    ObjectKind,
    ObjectSpec,
    Shape,
    Table,
)
from arrange_up.model.world import Push, WorldState
from arrange_up.physics.settings import (
    COMPLIANT_VALUES,
    CONTROLLER_VALUES,
    DEFAULT_SETTINGS,
    SERVO_VALUES,
    PhysicsSettings,
)
from arrange_up.physics.simulation import SimulationStatus, simulate

EAST = -math.pi / 2  # paddle theta that pushes toward +x


def _box(w: float, h: float) -> Shape:
    return Shape(parts=(((-w / 2, -h / 2), (w / 2, -h / 2), (w / 2, h / 2), (-w / 2, h / 2)),))


def _problem(servo: bool) -> ArrangementProblem:
    objects = (
        ObjectSpec("near", ObjectKind.PART, _box(1.0, 1.0)),
        ObjectSpec("far", ObjectKind.PART, _box(1.0, 1.0)),
        ObjectSpec("paddle", ObjectKind.MANIPULATOR, _box(2.5, 0.15)),
    )
    problem = ArrangementProblem(
        name="settings",
        table=Table((10.0, 5.0)),
        objects=objects,
        initial=(),
        goal=Goal(targets=(), tolerance=(0.1, 0.1, None)),
    )
    return dataclasses.replace(problem, controller=SERVO_CONTROLLER) if servo else problem


def _run(problem: ArrangementProblem, settings: PhysicsSettings, distance: float = 1.5):
    state = WorldState.from_mapping(problem, {"near": (3.0, 2.5, 0.0), "far": (8.0, 0.6, 0.0)})
    push = Push("paddle", (3.0 - 0.5 - 0.075 - 0.05, 2.5, EAST), distance)
    return simulate(problem, state, push, settings=settings)


def test_for_controller_fills_only_the_unset_fields():
    for kind, values in CONTROLLER_VALUES.items():
        resolved = DEFAULT_SETTINGS.for_controller(kind)
        assert {k: getattr(resolved, k) for k in values} == values
        assert resolved.for_controller(kind) == resolved  # nothing left to fill
    explicit = dataclasses.replace(DEFAULT_SETTINGS, iterations=7)
    for kind in ControllerKind:
        assert explicit.for_controller(kind).iterations == 7
    assert set(COMPLIANT_VALUES) == set(SERVO_VALUES)


def test_unresolved_settings_refuse_to_count_interval_steps():
    with pytest.raises(ValueError, match="for_controller"):
        DEFAULT_SETTINGS.interval_steps  # noqa: B018 - the property raises


@pytest.mark.parametrize("field", ["sleep_time", "rest_linear_tol"])
def test_negative_values_are_refused(field):
    with pytest.raises(ValueError, match=field):
        PhysicsSettings(**{field: -1.0})


@pytest.mark.parametrize("servo", [True, False])
def test_defaults_are_the_controllers_values_bit_for_bit(servo):
    """A push under the defaults is the push under its controller's values given explicitly;
    under the servo, those are the settings before they were chosen per controller."""
    problem = _problem(servo)
    values = SERVO_VALUES if servo else COMPLIANT_VALUES
    default = _run(problem, DEFAULT_SETTINGS)
    explicit = _run(problem, dataclasses.replace(DEFAULT_SETTINGS, **values))
    assert default == explicit
    assert default.status is SimulationStatus.OK


def test_sleeping_skips_idle_bodies_without_moving_them():
    problem = _problem(servo=False)
    awake = dataclasses.replace(DEFAULT_SETTINGS, **SERVO_VALUES)
    asleep = dataclasses.replace(awake, sleep_time=0.05)
    a, b = _run(problem, awake), _run(problem, asleep)
    assert b.status is SimulationStatus.OK
    assert b.state.pose("far") == a.state.pose("far") == (8.0, 0.6, 0.0)
    (xa, ya, ta), (xb, yb, tb) = a.state.pose("near"), b.state.pose("near")
    assert math.hypot(xa - xb, ya - yb) < 0.005 and abs(ta - tb) < 0.005
    assert xb > 3.0 + 1.0  # it was pushed


def test_compliant_defaults_take_fewer_steps_to_the_same_rest():
    """The compliant controller's values end a push in fewer steps than the servo's values
    would, with the pushed block where they would leave it (within 0.01 in)."""
    problem = _problem(servo=False)
    old = _run(problem, dataclasses.replace(DEFAULT_SETTINGS, **SERVO_VALUES), 0.55)
    new = _run(problem, DEFAULT_SETTINGS, 0.55)
    assert new.status is SimulationStatus.OK and old.status is SimulationStatus.OK
    assert new.steps < 0.8 * old.steps
    (xo, yo, to), (xn, yn, tn) = old.state.pose("near"), new.state.pose("near")
    assert math.hypot(xo - xn, yo - yn) < 0.01 and abs(to - tn) < 0.01
