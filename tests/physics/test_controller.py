"""The push controllers: the servo as it always was, the compliant PD tracking a moving set
point (stops short when resisted, never overshoots a free push), and the ``controller:`` key."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import pytest

from arrange_up.io.domains import load
from arrange_up.io.yaml_problem import load_problem_text
from arrange_up.model.errors import ProblemFormatError
from arrange_up.model.problem import (
    DEFAULT_CONTROLLER,
    SERVO_CONTROLLER,
    Controller,
    ControllerKind,
    ObjectKind,
    problem_hash,
)
from arrange_up.model.world import ActionNoise, Push, WorldState
from arrange_up.physics.bench import scene
from arrange_up.physics.settings import DEFAULT_SETTINGS
from arrange_up.physics.simulation import SimulationStatus, simulate, simulate_watched

COMPLIANT = Controller(kind=ControllerKind.COMPLIANT)
#: The compliant controller set from Python before every step, and solved by the engine.
WAYS = pytest.mark.parametrize(
    "settings",
    [replace(DEFAULT_SETTINGS, compliant_in_solver=way) for way in (False, True)],
    ids=["python", "solver"],
)
FRESH = Path(__file__).resolve().parents[1] / "problems" / "fresh"


def _noise(friction: float = 0.4, density: float = 0.125) -> ActionNoise:
    return ActionNoise((0.0, 0.0, 0.0), friction, density, 0.4)


def test_compliant_is_the_default_and_the_servo_hashes_as_problems_did_before_controllers():
    problem, state, push = scene("1 block")
    assert problem.controller == DEFAULT_CONTROLLER == COMPLIANT
    explicit = replace(problem, controller=Controller(kind=ControllerKind.COMPLIANT))
    assert problem_hash(explicit) == problem_hash(problem)
    assert simulate(explicit, state, push, _noise()) == simulate(problem, state, push, _noise())
    # The servo is left out of the hash (SERVO_CONTROLLER): a servo problem hashes as every
    # problem did before problems named their controller, the default one does not.
    servo = replace(problem, controller=SERVO_CONTROLLER)
    assert problem_hash(servo) != problem_hash(problem)
    # tz-mating's hash in the plan files written while the servo was every problem's controller.
    tz = replace(load("tz-mating"), controller=SERVO_CONTROLLER)
    assert problem_hash(tz) == (
        "sha256:f85ebb7f6bc916bfea2c633b951126c45d91a7e7fcba70eb40f58d55f32a1561"
    )


@WAYS
def test_compliant_free_push_ends_at_its_target_without_overshoot(settings):
    problem, _, push = scene("1 block")
    alone = tuple(o for o in problem.objects if o.kind is ObjectKind.MANIPULATOR)
    problem = replace(problem, objects=alone, controller=COMPLIANT)
    furthest = []

    def watch(bodies):
        if bodies is not None:
            furthest.append(bodies[-1][0] - push.pose[0])

    outcome = simulate_watched(problem, WorldState(()), push, watch, _noise(), settings)
    assert outcome.ok
    assert outcome.manipulator_travel == pytest.approx(push.distance, abs=1e-3)
    assert max(furthest) <= push.distance + 1e-3


@WAYS
def test_compliant_resisted_push_stops_short_more_under_more_friction_and_mass(settings):
    problem, state, push = scene("1 block")
    servo = simulate(replace(problem, controller=SERVO_CONTROLLER), state, push, _noise())
    problem = replace(problem, controller=COMPLIANT)
    light = simulate(problem, state, push, _noise(0.25, 0.1), settings)
    heavy = simulate(problem, state, push, _noise(0.55, 0.15), settings)
    assert servo.manipulator_travel == pytest.approx(push.distance, abs=1e-3)
    short_light = push.distance - light.manipulator_travel
    short_heavy = push.distance - heavy.manipulator_travel
    assert 0.0 < short_light < short_heavy
    # about friction / Kp: mu m g / Kp (the block's momentum carries it a little further)
    assert short_heavy == pytest.approx(0.55 * 0.15 * 386.09 / COMPLIANT.kp, rel=0.5)


@WAYS
def test_compliant_paddle_turns_against_its_controller_off_centre(settings):
    problem, state, push = scene("1 block")
    x, y, th = push.pose
    push = replace(push, pose=(x, y + 1.0, th))  # the block meets the paddle's end
    problem = replace(problem, controller=COMPLIANT)
    angles = []
    simulate_watched(
        problem,
        state,
        push,
        lambda b: b is None or angles.append(b[-1][2]),
        _noise(0.55),
        settings,
    )
    assert max(abs(a - th) for a in angles) > 1e-3


def test_the_solver_controller_ends_pushes_where_the_python_one_does():
    # The same PD: the chain into the wall and the lone block end within a few thousandths
    # of an inch of each other (their steps differ, so not bit for bit).
    python, solver = (replace(DEFAULT_SETTINGS, compliant_in_solver=w) for w in (False, True))
    for name in ("1 block", "7-block chain"):
        problem, state, push = scene(name)
        a = simulate(problem, state, push, _noise(), python)
        b = simulate(problem, state, push, _noise(), solver)
        assert a.ok and b.ok
        assert b.manipulator_travel == pytest.approx(a.manipulator_travel, abs=0.01)
        for (_, p), (_, q) in zip(a.state.poses, b.state.poses, strict=True):
            assert math.hypot(p[0] - q[0], p[1] - q[1]) < 0.02


def test_the_solver_controller_pushes_no_harder_than_its_clip():
    # A push commanded 5 in into the wall: the set point runs 3.5 in past the stalled paddle,
    # whose spring alone would pull with 1,050, but the clip holds it to 100: the chain is
    # not pushed (its friction needs about 135), as under the Python controller.
    problem, state, push = scene("7-block chain")
    clipped = replace(problem, controller=replace(COMPLIANT, force=100.0))
    for way in (False, True):
        s = replace(DEFAULT_SETTINGS, compliant_in_solver=way)
        free = simulate(problem, state, replace(push, distance=5.0), _noise(), s)
        held = simulate(clipped, state, replace(push, distance=5.0), _noise(), s)
        assert free.manipulator_travel > 1.0
        assert held.manipulator_travel < 0.5, way


_FILE = """
name: c
units: {length: cm}
table: {size: [25.4, 12.7]}
objects:
  b: {kind: part, shape: {box: [2.54, 2.54]}}
  paddle: {kind: manipulator, shape: {box: [6.35, 0.381]}}
initial:
  b: {pose: [7.62, 6.35, 0]}
goal:
  poses: {b: [12.7, 6.35, 0]}
"""


def test_controller_mapping_in_file_units():
    problem = load_problem_text(_FILE + "controller: {kind: compliant, kp: 200, speed: 2.54}\n")
    assert problem.controller.kind is ControllerKind.COMPLIANT
    assert problem.controller.kp == 200.0
    assert problem.controller.speed == pytest.approx(1.0)
    assert load_problem_text(_FILE).controller == DEFAULT_CONTROLLER


@pytest.mark.parametrize(
    ("mapping", "message"),
    [
        ("{kind: compliant, kpp: 3}", "unknown controller key 'kpp' (did you mean 'kp'?)"),
        ("{kind: stiff}", "expected compliant or servo"),
        ("{kind: servo, kp: 300}", "'kp' tunes the compliant controller only"),
        ("{kind: compliant, force: -1}", "expected a positive force"),
    ],
)
def test_controller_mapping_errors(mapping, message):
    with pytest.raises(ProblemFormatError) as error:
        load_problem_text(_FILE + f"controller: {mapping}\n")
    assert message in str(error.value)
    assert "controller" in str(error.value)


def test_default_angle_gain_makes_the_wrist_as_stiff_as_the_arm():
    from arrange_up.physics.simulation import DEFAULT_SETTINGS, compliant_gains

    gains = compliant_gains(COMPLIANT, DEFAULT_SETTINGS, 0.15, 0.08, 1.25, 400.0)
    # a force F at the paddle's end (1.25 in out) turns it by F r / Kp_angle, moving the end
    # F r^2 / Kp_angle: as far as F moves the centre, F / Kp
    assert 1.25 * 1.25 / gains.kp_angle == pytest.approx(1.0 / gains.kp)
    assert gains.kd == pytest.approx(math.sqrt(4 * 0.15 * gains.kp))
    assert gains.kd_angle == pytest.approx(math.sqrt(4 * 0.08 * gains.kp_angle))
    assert (gains.force, gains.speed) == (400.0, DEFAULT_SETTINGS.push_speed)
    assert gains.torque == pytest.approx(400.0 * 1.25)


def test_plan_files_record_the_controller():
    from arrange_up.io.planfile import plan_document

    default = load_problem_text(_FILE)
    servo = load_problem_text(_FILE + "controller: {kind: servo, speed: 2.54}\n")
    compliant = load_problem_text(_FILE + "controller: {kind: compliant, speed: 2.54}\n")
    kw = {"status": "solved", "semantics": "deterministic", "seed": 0, "search": {}}
    assert plan_document(default, (), **kw)["controller"] == {"kind": "compliant", "kp": 300.0}
    # The servo's record names only the keys the servo reads.
    assert plan_document(servo, (), **kw)["controller"] == {"kind": "servo", "speed": 2.54}
    recorded = plan_document(compliant, (), **kw)["controller"]
    assert recorded == {"kind": "compliant", "kp": 300.0, "speed": 2.54}  # in the file's cm


def test_a_wedged_compliant_push_comes_to_rest_with_more_solver_iterations():
    # A rollout of squeeze-post's plan: the paddle, turned by its approach noise, presses the
    # tilted block into the bottom wall. At 5 solver iterations the wedge chatters (the paddle
    # oscillates by about 0.03 in) until the 20 s cap; raised to 20 after 1 s past the set
    # point's end, it settles in under 2.5 s with the block where it was pressed.
    problem = load(FRESH / "squeeze-post.yaml")
    state = WorldState((("A", (5.4344524222650294, 0.5620389201441705, 0.14044835920831922)),))
    push = Push("paddle", (4.627788, 1.54475, math.radians(-180.0)), 1.4697)
    noise = ActionNoise(
        pose_offset=(-0.005267972242585572, -0.09738029668683373, -0.03337826740161486),
        friction=0.624535399920112,
        part_density=0.125,
        manipulator_density=0.4,
    )
    settled = simulate(problem, state, push, noise)
    assert settled.status is SimulationStatus.OK
    assert settled.sim_time < 2.5
    x, y, _ = settled.state.as_dict()["A"]
    assert abs(x - 5.41) < 0.02 and abs(y - 0.59) < 0.02
    chattering = simulate(problem, state, push, noise, replace(DEFAULT_SETTINGS, stuck_time=0.0))
    assert chattering.status is SimulationStatus.NOT_AT_REST
