"""Tests of arrange_up.physics (simulation, bodies, settings): place, pick and push on small
problems built in code."""

from __future__ import annotations

import dataclasses
import math
import os
import subprocess
import sys
from pathlib import Path

import catalogue
import numpy as np
import pytest

from arrange_up.io.yaml_problem import load_problem
from arrange_up.model.problem import (
    SERVO_CONTROLLER,
    ArrangementProblem,
    ControllerKind,
    Goal,
    ObjectKind,
    ObjectSpec,
    Shape,
    Table,
    Uncertainty,
)
from arrange_up.model.world import ActionNoise, Pick, Place, Push, WorldState, draw_noise
from arrange_up.physics.bodies import _abs_r_integral
from arrange_up.physics.simulation import (
    DEFAULT_SETTINGS,
    PhysicsSettings,
    SimulationStatus,
    _drive_trajectory,
    pd_gains,
    push_force,
    simulate,
)

ROOT = Path(__file__).resolve().parents[2]
PADDLE_HALF = 0.075  # half the paddle's thickness
EAST = -math.pi / 2  # paddle theta that pushes toward +x
NORTH = 0.0  # paddle theta that pushes toward +y


def box(width: float, height: float) -> Shape:
    w, h = width / 2, height / 2
    return Shape(parts=(((-w, -h), (w, -h), (w, h), (-w, h)),), box=(width, height))


def make_problem(
    blocks: int = 1,
    walls: tuple[str, ...] = ("left", "right", "bottom", "top"),
    obstacle: tuple[float, float, float] | None = None,
    fixture: bool = False,
    uncertainty: Uncertainty | None = None,
) -> ArrangementProblem:
    objects = [ObjectSpec(f"b{i}", ObjectKind.PART, box(1.0, 1.0)) for i in range(blocks)]
    objects.append(ObjectSpec("paddle", ObjectKind.MANIPULATOR, box(2.5, 0.15)))
    objects.append(ObjectSpec("paddle2", ObjectKind.MANIPULATOR, box(2.5, 0.15)))
    if fixture:
        objects.append(ObjectSpec("fix", ObjectKind.FIXTURE, box(0.5, 2.0)))
    if obstacle is not None:
        objects.append(ObjectSpec("rock", ObjectKind.OBSTACLE, box(1.0, 1.0), pose=obstacle))
    return ArrangementProblem(
        name="test",
        table=Table((10.0, 5.0), walls),
        objects=tuple(objects),
        initial=(),
        goal=Goal(targets=(), tolerance=(0.1, 0.1, None)),
        uncertainty=uncertainty or Uncertainty(),
    )


def state_of(problem: ArrangementProblem, **poses) -> WorldState:
    return WorldState.from_mapping(problem, poses)


def push_east(x_block: float, y: float, distance: float, gap: float = 0.05) -> Push:
    """A push toward +x from just left of a 1-inch block centred at ``x_block``."""
    return Push("paddle", (x_block - 0.5 - PADDLE_HALF - gap, y, EAST), distance)


def angle_mod_90(theta: float) -> float:
    """Distance of ``theta`` from the nearest multiple of 90 degrees (rad)."""
    r = math.remainder(theta, math.pi / 2)
    return abs(r)


# --- pushing -----------------------------------------------------------------------------------


def test_block_pushed_against_wall_ends_against_it():
    problem = make_problem(1)
    state = state_of(problem, b0=(7.0, 2.5, 0.0))
    outcome = simulate(problem, state, push_east(7.0, 2.5, 5.0))
    assert outcome.status is SimulationStatus.OK
    x, y, theta = outcome.state.pose("b0")
    assert x == pytest.approx(10.0 - 0.5, abs=0.02)
    assert y == pytest.approx(2.5, abs=0.02)
    assert angle_mod_90(theta) < 0.01
    # the paddle stalled against the block, well short of its 5-inch reference
    assert 2.3 < outcome.manipulator_travel < 2.6
    assert outcome.steps > 0 and outcome.sim_time == pytest.approx(
        outcome.steps * DEFAULT_SETTINGS.dt
    )


def test_force_clip_grows_with_heavy_parts_only():
    """Light problems keep the default clip; a problem of dense parts gets 1.5 times the
    friction of all its parts at nominal parameters, so the robot moves them under nominal
    parameters but stalls on the heaviest, most frictional draws."""
    assert push_force(make_problem(7)) == DEFAULT_SETTINGS.push_force
    heavy = Uncertainty(friction=(0.4, 0.4), part_density=(2.0, 4.0))
    problem = make_problem(1, uncertainty=heavy)
    nominal_load = DEFAULT_SETTINGS.gravity * 0.4 * 3.0 * 1.0  # one 1 x 1 in block
    assert push_force(problem) == pytest.approx(1.5 * nominal_load)
    # The servo (the compliant controller would stop short by about friction / Kp, 1.5 in here).
    problem = dataclasses.replace(problem, controller=SERVO_CONTROLLER)
    state = state_of(problem, b0=(5.0, 2.5, 0.0))
    nominal = ActionNoise(friction=0.4, part_density=3.0)
    moved = simulate(problem, state, push_east(5.0, 2.5, 1.0), nominal)
    assert moved.ok and moved.state.pose("b0")[0] > 5.8
    # Twice the nominal density needs more than the clip: the push stalls where it touches.
    stalled = simulate(
        problem, state, push_east(5.0, 2.5, 1.0), ActionNoise(friction=0.4, part_density=6.0)
    )
    assert stalled.ok and stalled.state.pose("b0")[0] < 5.05


def test_push_that_misses_moves_nothing():
    problem = make_problem(2)
    state = state_of(problem, b0=(3.0, 0.6, 0.1), b1=(6.0, 4.4, -0.2))
    # the paddle (y from 1.25 to 3.75) passes between the blocks (b0 below 1.15, b1 above 3.81)
    outcome = simulate(problem, state, Push("paddle", (1.0, 2.5, EAST), 7.0))
    assert outcome.ok
    assert outcome.manipulator_travel == pytest.approx(7.0, abs=0.05)
    for (name, before), (name2, after) in zip(state.poses, outcome.state.poses, strict=True):
        assert name == name2
        assert after == pytest.approx(before, abs=1e-6)


def test_three_block_chain_pushed_to_wall_ends_compressed():
    problem = make_problem(3)
    state = state_of(problem, b0=(4.0, 2.5, 0.0), b1=(5.3, 2.5, 0.0), b2=(6.6, 2.5, 0.0))
    outcome = simulate(problem, state, push_east(4.0, 2.5, 6.0))
    assert outcome.ok
    xs = [outcome.state.pose(n)[0] for n in ("b0", "b1", "b2")]
    assert xs[2] == pytest.approx(9.5, abs=0.02)
    for left, right in zip(xs, xs[1:], strict=False):
        assert right - left == pytest.approx(1.0, abs=0.02)  # touching: gaps closed
    for name in ("b0", "b1", "b2"):
        _, y, theta = outcome.state.pose(name)
        assert y == pytest.approx(2.5, abs=0.05)
        assert angle_mod_90(theta) < 0.02


def test_push_north_and_obstacle_stops_block():
    problem = make_problem(1, obstacle=(3.0, 4.0, 0.0))
    state = state_of(problem, b0=(3.0, 1.5, 0.0))
    push = Push("paddle", (3.0, 1.5 - 0.5 - PADDLE_HALF - 0.05, NORTH), 4.0)
    outcome = simulate(problem, state, push)
    assert outcome.ok
    x, y, _ = outcome.state.pose("b0")
    assert y == pytest.approx(4.0 - 1.0, abs=0.02)  # against the obstacle's lower face
    assert x == pytest.approx(3.0, abs=0.02)


def test_part_pushed_off_an_open_edge_is_off_table():
    problem = make_problem(1, walls=("left", "bottom", "top"))
    state = state_of(problem, b0=(8.5, 2.5, 0.0))
    outcome = simulate(problem, state, push_east(8.5, 2.5, 2.5))
    assert outcome.status is SimulationStatus.OFF_TABLE
    assert outcome.off_table == ("b0",)
    assert outcome.state.pose("b0")[0] > 10.0
    assert not outcome.ok


def test_rest_cap_reports_not_at_rest():
    problem = make_problem(1)
    state = state_of(problem, b0=(3.0, 2.5, 0.0))
    push = push_east(3.0, 2.5, 2.0)
    # the set point reaches its end after 2 / 3 s: the cap is the later of max_time and that
    # end plus travel_margin
    settings = PhysicsSettings(max_time=0.05, travel_margin=0.05)
    capped = simulate(problem, state, push, settings=settings)
    assert capped.status is SimulationStatus.NOT_AT_REST
    assert capped.sim_time == pytest.approx(2.0 / 3.0 + 0.05, abs=DEFAULT_SETTINGS.dt)
    normal = simulate(problem, state, push)
    assert normal.status is SimulationStatus.OK
    assert 0.5 < normal.sim_time < 3.0


def test_a_long_push_is_not_cut_off_before_it_could_arrive():
    # 100 inches at the default 3 in/s take 33 s, beyond the 20-s cap: before the cap made room
    # for the travel, every such push (a metre-scale problem's) ended NOT_AT_REST.
    problem = dataclasses.replace(make_problem(1), table=Table((120.0, 5.0)))
    state = state_of(problem, b0=(10.0, 2.5, 0.0))
    outcome = simulate(problem, state, push_east(10.0, 2.5, 112.0))
    assert outcome.status is SimulationStatus.OK, outcome.status
    assert outcome.state.pose("b0")[0] == pytest.approx(120.0 - 0.5, abs=0.05)
    assert outcome.sim_time > DEFAULT_SETTINGS.max_time
    # ...but no longer than the time to cross the table: a plan file may command 1e300 in
    endless = simulate(problem, state, push_east(10.0, 2.5, 1e300))
    crossing = (math.hypot(120.0, 5.0) + 2.0 * math.hypot(1.25, 0.075)) / 3.0
    assert endless.sim_time <= crossing + DEFAULT_SETTINGS.travel_margin + 0.1


def test_overlapping_approach_is_reported():
    problem = make_problem(1)
    state = state_of(problem, b0=(3.0, 2.5, 0.0))
    outcome = simulate(problem, state, Push("paddle", (2.6, 2.5, EAST), 1.0))  # inside b0
    assert outcome.status is SimulationStatus.OVERLAP


@pytest.mark.parametrize("theta", [EAST, NORTH])
def test_paddle_put_down_centred_on_a_block_is_reported(theta):
    # Chipmunk builds no contact for two concentric symmetric polygons; the landing test is
    # geometric, so the paddle's thickness (0.15 in) is the depth found.
    problem = make_problem(1)
    state = state_of(problem, b0=(3.0, 2.5, 0.0))
    outcome = simulate(problem, state, Push("paddle", (3.0, 2.5, theta), 1.0))
    assert outcome.status is SimulationStatus.OVERLAP
    assert outcome.overlap == pytest.approx(2 * PADDLE_HALF)
    assert outcome.overlap > DEFAULT_SETTINGS.overlap_tolerance


def test_resting_manipulator_and_fixture_are_bodies():
    problem = make_problem(1, fixture=True)
    state = state_of(problem, b0=(3.0, 2.5, 0.0), fix=(6.0, 2.5, 0.0))
    outcome = simulate(problem, state, push_east(3.0, 2.5, 4.0))
    assert outcome.ok
    # the fixture is clamped: the block is pushed against it and ends touching it, unmoved
    b0, fix = outcome.state.pose("b0"), outcome.state.pose("fix")
    assert fix == (6.0, 2.5, 0.0)
    assert fix[0] - 0.25 - (b0[0] + 0.5) == pytest.approx(0.0, abs=0.02)
    # a manipulator lying on the table is an obstacle to another one's push
    state2 = state_of(problem, b0=(3.0, 2.5, 0.0), paddle2=(5.0, 2.5, EAST))
    outcome2 = simulate(problem, state2, push_east(3.0, 2.5, 5.0))
    assert outcome2.ok
    assert outcome2.state.pose("b0")[0] > 4.0


# --- the controller ----------------------------------------------------------------------------


def clipped_pd_reference(mass, start, ref, n_steps, settings):
    """The thesis's clipped PD, F = clip(Kd (clip(Kp/Kd e, v_max) - v)), Kd = sqrt(4 m Kp),
    integrated like pymunk integrates (positions with the old velocity, then velocities)."""
    kp, kd = pd_gains(mass, settings)
    dt = settings.dt
    x, y = start
    vx = vy = 0.0
    out = []
    for _ in range(n_steps):
        x, y = x + vx * dt, y + vy * dt
        wx, wy = kp / kd * (ref[0] - x), kp / kd * (ref[1] - y)
        speed = math.hypot(wx, wy)
        if speed > settings.push_speed:
            wx, wy = wx / speed * settings.push_speed, wy / speed * settings.push_speed
        fx, fy = kd * (wx - vx), kd * (wy - vy)
        force = math.hypot(fx, fy)
        if force > settings.push_force:
            fx, fy = fx / force * settings.push_force, fy / force * settings.push_force
        vx, vy = vx + fx / mass * dt, vy + fy / mass * dt
        out.append((x, y, vx, vy))
    return out


@pytest.mark.parametrize("push_force", [DEFAULT_SETTINGS.push_force, 20.0])
def test_c_side_drive_is_the_clipped_critically_damped_pd(push_force):
    settings = PhysicsSettings(push_force=push_force)
    mass, start, ref, n = 0.16, (1.0, 2.0), (2.5, 3.0), 240
    kp, kd = pd_gains(mass, settings)
    assert kd == pytest.approx(math.sqrt(4 * mass * kp))  # critically damped
    got = np.array(_drive_trajectory(mass, start, ref, n, settings))
    want = np.array(clipped_pd_reference(mass, start, ref, n, settings))
    assert np.abs(got - want).max() < 1e-9
    # speed never above the limit, force never above the clip
    speeds = np.hypot(got[:, 2], got[:, 3])
    assert speeds.max() <= settings.push_speed * (1 + 1e-9)
    velocities = np.vstack([[0.0, 0.0], got[:, 2:]])
    forces = mass * np.hypot(*np.diff(velocities, axis=0).T) / settings.dt
    assert forces.max() <= push_force * (1 + 1e-9)
    if push_force < 100:
        assert forces.max() == pytest.approx(push_force)  # the clip was hit
    # approach without overshoot: the distance to the reference never grows, and ends ~0
    along = (got[:, 0] - start[0]) * (ref[0] - start[0]) + (got[:, 1] - start[1]) * (
        ref[1] - start[1]
    )
    along /= math.hypot(ref[0] - start[0], ref[1] - start[1])
    total = math.hypot(ref[0] - start[0], ref[1] - start[1])
    assert np.all(np.diff(along) >= -1e-12)
    assert along.max() <= total + 1e-12
    assert along[-1] == pytest.approx(total, abs=1e-4)


@pytest.mark.parametrize("distance", [1.0, 4.0])
def test_free_push_stops_near_reference_in_realistic_time(distance):
    problem = make_problem(0)
    outcome = simulate(problem, WorldState(()), Push("paddle", (2.0, 2.5, EAST), distance))
    assert outcome.ok
    assert outcome.manipulator_travel == pytest.approx(distance, abs=0.05)
    # speed limit 3 in/s plus the rest checks: a 1-5 inch push takes about 0.5-2.5 s
    assert distance / DEFAULT_SETTINGS.push_speed < outcome.sim_time < distance / 3.0 + 1.0


# --- place, pick, errors -----------------------------------------------------------------------


def test_place_applies_noise_offset_and_pick_removes():
    problem = make_problem(2)
    state = state_of(problem, b1=(6.0, 2.0, 0.0))
    noise = ActionNoise(pose_offset=(0.01, -0.02, 0.03))
    placed = simulate(problem, state, Place("b0", (2.0, 3.0, 0.5)), noise)
    assert placed.ok and placed.steps == 0
    assert placed.state.names() == ("b0", "b1")  # the problem's order
    assert placed.state.pose("b0") == pytest.approx((2.01, 2.98, 0.53))
    assert placed.state.pose("b1") == (6.0, 2.0, 0.0)
    picked = simulate(problem, placed.state, Pick("b1"))
    assert picked.ok and picked.state.names() == ("b0",)
    off = simulate(problem, state, Place("b0", (10.2, 3.0, 0.0)))
    assert off.status is SimulationStatus.OFF_TABLE and off.off_table == ("b0",)


@pytest.mark.parametrize(
    ("poses", "action", "message"),
    [
        ({"b0": (2.0, 2.0, 0.0)}, Place("b0", (5.0, 2.0, 0.0)), "already on the table"),
        ({}, Pick("b0"), "not on the table"),
        ({"paddle": (5.0, 2.0, 0.0)}, Push("paddle", (2.0, 2.0, 0.0), 1.0), "already on"),
        ({"b0": (2.0, 2.0, 0.0)}, Push("b0", (2.0, 2.0, 0.0), 1.0), "not a manipulator"),
        ({}, Push("ghost", (2.0, 2.0, 0.0), 1.0), "unknown object"),
        ({}, Place("ghost", (2.0, 2.0, 0.0)), "unknown object"),
        ({}, Pick("ghost"), "unknown object"),
        ({}, Place("paddle", (2.0, 2.0, 0.0)), "manipulator"),
        ({}, Place("rock", (2.0, 2.0, 0.0)), "obstacle"),
        ({}, Pick("rock"), "obstacle"),
        ({}, Push("rock", (2.0, 2.0, 0.0), 1.0), "not a manipulator"),
        ({}, Push("paddle", (2.0, 2.0, 0.0), -1.0), "non-negative"),
        ({}, Push("paddle", (2.0, 2.0, 0.0), math.nan), "finite"),
    ],
)
def test_invalid_actions_raise(poses, action, message):
    problem = make_problem(1, obstacle=(8.0, 1.0, 0.0))
    with pytest.raises(ValueError, match=message):
        simulate(problem, WorldState.from_mapping(problem, poses), action)


def test_invalid_states_raise():
    problem = make_problem(1, obstacle=(8.0, 1.0, 0.0))
    with pytest.raises(ValueError, match="obstacle"):
        simulate(problem, WorldState((("rock", (8.0, 1.0, 0.0)),)), Pick("rock"))
    with pytest.raises(ValueError, match="unknown object"):
        simulate(problem, WorldState((("ghost", (1.0, 1.0, 0.0)),)), Pick("ghost"))
    with pytest.raises(ValueError, match="twice"):
        twice = WorldState((("b0", (1.0, 1.0, 0.0)), ("b0", (3.0, 1.0, 0.0))))
        simulate(problem, twice, Pick("b0"))


# --- rollouts, determinism ---------------------------------------------------------------------

_DETERMINISM_SCRIPT = """
import math
from arrange_up.physics.simulation import simulate
from arrange_up.model.problem import *
from arrange_up.model.world import *
w, h = 0.5, 0.5
sq = Shape(parts=(((-w, -h), (w, -h), (w, h), (-w, h)),))
pad = Shape(parts=(((-1.25, -0.075), (1.25, -0.075), (1.25, 0.075), (-1.25, 0.075)),))
objs = tuple(ObjectSpec(f"b{i}", ObjectKind.PART, sq) for i in range(3)) + (
    ObjectSpec("paddle", ObjectKind.MANIPULATOR, pad),)
p = ArrangementProblem("d", Table((10.0, 5.0)), objs, (), Goal((), (0.1, 0.1, None)))
s = WorldState.from_mapping(p, {"b0": (4.0, 2.4, 0.05), "b1": (5.2, 2.7, -0.1),
                                "b2": (6.5, 2.3, 0.2)})
n = ActionNoise((0.003, -0.01, 0.02), 0.37, 0.11, 0.41)
o = simulate(p, s, Push("paddle", (3.3, 2.5, -math.pi / 2 + 0.1), 4.0), n)
print(repr(o.state.poses), o.steps, repr(o.manipulator_travel))
"""


def test_push_is_bit_identical_across_processes():
    outputs = set()
    for hash_seed in ("1", "12345"):
        env = dict(os.environ, PYTHONHASHSEED=hash_seed, PYTHONPATH=str(ROOT))
        result = subprocess.run(
            [sys.executable, "-c", _DETERMINISM_SCRIPT],
            capture_output=True,
            text=True,
            env=env,
            check=True,
            cwd=ROOT,
        )
        outputs.add(result.stdout)
    assert len(outputs) == 1
    # and in this process too
    namespace: dict = {}
    from contextlib import redirect_stdout
    from io import StringIO

    buffer = StringIO()
    with redirect_stdout(buffer):
        exec(_DETERMINISM_SCRIPT, namespace)
    assert buffer.getvalue() in outputs


# --- geometry of table friction ----------------------------------------------------------------


def test_abs_r_integral_closed_form():
    square = ((-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5))
    expected = (math.sqrt(2) + math.asinh(1.0)) / 6  # = 0.3826 for a unit square
    assert _abs_r_integral(square) == pytest.approx(expected, rel=1e-12)
    # a part away from the origin (as the parts of an L-shape are): compare with a fine grid
    part = ((0.2, -0.3), (1.4, -0.1), (1.1, 0.9), (0.3, 0.6))
    n = 1000
    xs = np.linspace(0.2, 1.4, n)
    ys = np.linspace(-0.3, 0.9, n)
    gx, gy = np.meshgrid(xs, ys)
    inside = np.ones_like(gx, dtype=bool)
    for (ax, ay), (bx, by) in zip(part, part[1:] + part[:1], strict=True):
        inside &= (bx - ax) * (gy - ay) - (by - ay) * (gx - ax) >= 0
    cell = (xs[1] - xs[0]) * (ys[1] - ys[0])
    numeric = float((np.hypot(gx, gy) * inside).sum() * cell)
    assert _abs_r_integral(part) == pytest.approx(numeric, rel=5e-3)


def test_settings_validation():
    with pytest.raises(ValueError):
        PhysicsSettings(dt=0.0)
    with pytest.raises(ValueError):
        PhysicsSettings(damping_ratio=0.3)
    assert DEFAULT_SETTINGS.for_controller(ControllerKind.SERVO).interval_steps == 24
    assert DEFAULT_SETTINGS.max_steps == 4800


def test_bench_physics_runs_in_process():
    from arrange_up.physics.bench import SCENES, bench_physics

    messages: list[str] = []
    rows = bench_physics(n_pushes=3, workers=(1,), progress=messages.append)
    assert [row["scene"] for row in rows] == list(SCENES)
    for row in rows:
        assert row["workers"] == 1 and row["pushes"] == 3
        assert row["not_at_rest"] == 0 and row["not_ok"] == 0
        assert row["pushes_per_second"] > 0
    assert len(messages) == len(SCENES)


def test_a_chattering_press_into_a_wall_ends_its_drive_once_stalled():
    # fence-row's press of B into the bottom wall with A elsewhere on the table: in this noise
    # draw the wedge of paddle, B and wall chatters (B creeping along the wall) with every
    # check-to-check rest test failing, so without the stall window it ran to the 20 s cap.
    problem = load_problem(ROOT / "tests" / "problems" / "fresh" / "fence-row.yaml")
    push = Push("paddle", (6.0, 4.266, -math.pi), 4.191)
    rng = np.random.default_rng(1)
    theta, noise = rng.uniform(-0.09, 0.09), draw_noise(problem, push, rng)
    state = WorldState.from_mapping(problem, {"B": (6.0, 3.0, theta), "A": (2.0, 3.0, 0.0)})
    chattering = simulate(problem, state, push, noise, PhysicsSettings(stall_window=0.0))
    assert chattering.status is SimulationStatus.NOT_AT_REST
    outcome = simulate(problem, state, push, noise)
    assert outcome.status is SimulationStatus.OK
    assert outcome.sim_time < 5.0
    x, y, th = outcome.state.pose("B")
    assert y == pytest.approx(0.5, abs=0.01)  # pressed against the wall
    assert abs(th) < 0.02


def test_a_controller_too_stiff_for_a_light_paddle_is_named_with_the_gain_that_is_not():
    # An 8 x 0.5 mm paddle weighs about 0.0025: the default kp of 300 is far beyond what the
    # explicitly integrated PD follows at 1/240 s, and its pushes throw the chip off the table.
    from arrange_up.physics.simulation import STABLE_RATE, stiff_manipulators

    tiny = catalogue.tiny("millimetre-paddle")
    [stiff] = stiff_manipulators(tiny)
    assert stiff.name == "tip" and stiff.rate > 2 * STABLE_RATE and 1.0 < stiff.kp_max < 300.0
    controller = dataclasses.replace(tiny.controller, kp=stiff.kp_max)
    at_limit = dataclasses.replace(tiny, controller=controller)
    assert stiff_manipulators(at_limit) == []
    servo = dataclasses.replace(tiny, controller=SERVO_CONTROLLER)
    assert stiff_manipulators(servo) == []
    assert stiff_manipulators(make_problem(1)) == []  # the block worlds' paddle at kp 300
