"""Controller benchmark: how the push controllers behave, measured push by push.

Usage::

    python benchmarks/controller.py [--pushes 30] [--kp 150,300,600] [--rollouts 40]
        [--fixed] [--seed 0] [--output controller-bench.csv]

Scenes (10 x 5 in board with walls, the thesis's 2.5 x 0.15 in paddle, 1-inch blocks; every
push draws friction in [0.25, 0.55], part density in [0.1, 0.15], manipulator density in
[0.35, 0.45] and an approach offset of +-0.02 in, +-0.01 rad):

* ``free``: the paddle alone pushed 0.5, 1, 2 and 5 in (cycled). Reports the end error
  (travel - commanded distance) and the overshoot (the furthest the paddle got past its
  target during the push).
* ``resisted``: one block pushed 0.5, 1, 2 or 5 in across the open table. Reports the stall
  (commanded - travel), its correlation with friction x block mass (per distance, averaged)
  and the gap left between the paddle's face and the block at rest (``thrown``: > 0 means it
  left the paddle).
* ``row``: a gathered row of four touching blocks pushed 3 in across the open table; a run
  *scatters* when neighbouring blocks end more than 0.1 in apart or off the row's line by more
  than 0.1 in.
* ``wall``: the 7-block chain of ``arrange_up.physics.bench`` pushed 2.5 and 5 in into the
  right wall. Reports the deepest any block went into the wall during the push.

For every scene: the fastest block and paddle speeds seen in any step (in/s) and the paddle's
longest travel in one step (in; tunnelling begins near 0.25 in for 1-inch blocks at these
speeds). Each controller is a row: ``servo`` and ``compliant`` at each ``--kp`` (and, with
``--fixed``, ``compliant`` with its set point at the push's end from the start).

Finally the speed of rollouts of the shipped blocks-7's nominal plan (planned under the servo)
under ``servo`` and ``compliant`` at the first ``--kp``, one process, in 5 interleaved rounds
of one run (medians):
rollouts and actions simulated per second, the plan's pushes per second (each from the state the
servo's noise-free execution reaches, noise-free), and their ratios.
"""

from __future__ import annotations

import argparse
import csv
import math
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from arrange_up.evaluation.rollouts import Rollouts
from arrange_up.io.domains import load
from arrange_up.model.problem import (
    SERVO_CONTROLLER,
    ArrangementProblem,
    Controller,
    ControllerKind,
    ObjectKind,
)
from arrange_up.model.world import Push, WorldState, draw_noise
from arrange_up.physics.bench import scene
from arrange_up.physics.simulation import (
    DEFAULT_SETTINGS,
    PhysicsSettings,
    simulate,
    simulate_watched,
)
from arrange_up.planning.planner import plan

DISTANCES = (0.5, 1.0, 2.0, 5.0)
ROUNDS = 5  # interleaved servo / compliant speed rounds
FIXED_SPEED = 1e9  # in/s: the set point is at the push's end from the first step
WALL_X = 10.0
FIELDS = [
    "controller",
    "kp",
    "free_end_error_max",
    "free_overshoot_max",
    "resisted_stall_median",
    "resisted_stall_max",
    "stall_vs_friction_mass_r",
    "thrown_max",
    "row_scattered",
    "row_runs",
    "wall_penetration_max",
    "block_speed_max",
    "paddle_speed_max",
    "paddle_step_max",
    "not_ok",
]


class Watch:
    """Collects the fastest speeds, the paddle's furthest progress along its push line and
    the deepest wall penetration over one push's steps (``simulate_watched``)."""

    def __init__(self, start: tuple[float, float], direction: tuple[float, float]) -> None:
        self.start, self.direction = start, direction
        self.block_speed = self.paddle_speed = self.furthest = 0.0
        self.wall = -math.inf
        self.driving = True

    def __call__(self, bodies: list | None) -> None:
        if bodies is None:
            self.driving = False
            return
        *blocks, paddle = bodies
        for x, _, a, vx, vy, _ in blocks:
            self.block_speed = max(self.block_speed, math.hypot(vx, vy))
            reach = 0.5 * (abs(math.cos(a)) + abs(math.sin(a)))
            self.wall = max(self.wall, x + reach - WALL_X)
        x, y, _, vx, vy, _ = paddle
        self.paddle_speed = max(self.paddle_speed, math.hypot(vx, vy))
        if self.driving:
            along = (x - self.start[0]) * self.direction[0] + (y - self.start[1]) * self.direction[
                1
            ]
            self.furthest = max(self.furthest, along)


def _push_with(
    problem: ArrangementProblem,
    state: WorldState,
    push: Push,
    rng: np.random.Generator,
    settings: PhysicsSettings = DEFAULT_SETTINGS,
):
    noise = draw_noise(problem, push, rng)
    px, py, pth = push.pose
    ox, oy, oth = noise.pose_offset
    start = (px + ox, py + oy)
    direction = (-math.sin(pth + oth), math.cos(pth + oth))  # the paddle's +y
    watch = Watch(start, direction)
    outcome = simulate_watched(problem, state, push, watch, noise, settings)
    return outcome, noise, watch


def _row_state(problem: ArrangementProblem, count: int) -> tuple[WorldState, Push]:
    y = 2.5
    poses = {f"block{i}": (2.0 + i * 1.001, y, 0.0) for i in range(count)}
    state = WorldState.from_mapping(problem, poses)
    return state, Push("paddle", (2.0 - 0.5 - 0.075 - 0.1, y, -math.pi / 2.0), 3.0)


def measure(
    controller: Controller, pushes: int, seed: int, settings: PhysicsSettings = DEFAULT_SETTINGS
) -> dict:
    """The :data:`FIELDS` but ``controller`` and ``kp`` of ``controller`` under ``settings``,
    over ``pushes`` pushes of each scene (module docstring)."""
    rng = np.random.default_rng(seed)
    step = settings.dt
    speeds = {"block": 0.0, "paddle": 0.0}
    not_ok = 0

    def note(watch: Watch, outcome) -> None:
        nonlocal not_ok
        speeds["block"] = max(speeds["block"], watch.block_speed)
        speeds["paddle"] = max(speeds["paddle"], watch.paddle_speed)
        not_ok += not outcome.ok

    # free: the paddle alone
    problem, _, push = scene("1 block")
    problem = replace(
        problem,
        objects=tuple(o for o in problem.objects if o.kind is ObjectKind.MANIPULATOR),
        controller=controller,
    )
    end_errors, overshoots = [], []
    for i in range(pushes):
        d = DISTANCES[i % len(DISTANCES)]
        outcome, _, watch = _push_with(
            problem, WorldState(()), replace(push, distance=d), rng, settings
        )
        note(watch, outcome)
        end_errors.append(outcome.manipulator_travel - d)
        overshoots.append(max(0.0, watch.furthest - d))

    # resisted: one block across the open table
    problem, state, push = scene("1 block")
    problem = replace(problem, controller=controller)
    stalls, loads, thrown = [], [], []
    for i in range(pushes):
        d = DISTANCES[i % len(DISTANCES)]
        outcome, noise, watch = _push_with(problem, state, replace(push, distance=d), rng, settings)
        note(watch, outcome)
        stalls.append(d - outcome.manipulator_travel)
        loads.append(noise.friction * noise.part_density * 1.0)  # block area 1 in^2
        # gap between the paddle's face (half its 0.15 in thickness ahead of its centre) and
        # the block's back face, at rest: > 0 when the block left the paddle
        face = watch.start[0] + outcome.manipulator_travel + 0.075
        thrown.append(outcome.state.poses[0][1][0] - 0.5 - face)
    # Correlation within each distance (pushes of different lengths stall alike), pooled.
    rs = []
    for k in range(len(DISTANCES)):
        s, f = np.array(stalls[k :: len(DISTANCES)]), np.array(loads[k :: len(DISTANCES)])
        if len(s) > 2 and np.std(s) > 0 and np.std(f) > 0:
            rs.append(float(np.corrcoef(s, f)[0, 1]))

    # row: four touching blocks
    problem, _, _ = scene("7-block chain")
    four = tuple(o for o in problem.objects if o.name in {f"block{i}" for i in range(4)})
    paddle = tuple(o for o in problem.objects if o.kind is ObjectKind.MANIPULATOR)
    problem = replace(problem, objects=four + paddle, controller=controller)
    state, push = _row_state(problem, 4)
    scattered = 0
    for _ in range(pushes):
        outcome, _, watch = _push_with(problem, state, push, rng, settings)
        note(watch, outcome)
        xs = [p[0] for _, p in outcome.state.poses]
        ys = [p[1] for _, p in outcome.state.poses]
        gaps = np.diff(sorted(xs)) - 1.0
        scattered += bool(gaps.max() > 0.1 or max(ys) - min(ys) > 0.1)

    # wall: the 7-block chain into the right wall
    problem, state, push = scene("7-block chain")
    problem = replace(problem, controller=controller)
    wall = -math.inf
    for i in range(pushes):
        d = (2.5, 5.0)[i % 2]
        outcome, _, watch = _push_with(problem, state, replace(push, distance=d), rng, settings)
        note(watch, outcome)
        wall = max(wall, watch.wall)

    return {
        "free_end_error_max": max(abs(e) for e in end_errors),
        "free_overshoot_max": max(overshoots),
        "resisted_stall_median": float(np.median(stalls)),
        "resisted_stall_max": max(stalls),
        "stall_vs_friction_mass_r": float(np.mean(rs)) if rs else float("nan"),
        "thrown_max": max(thrown),
        "row_scattered": scattered,
        "row_runs": pushes,
        "wall_penetration_max": wall,
        "block_speed_max": speeds["block"],
        "paddle_speed_max": speeds["paddle"],
        "paddle_step_max": speeds["paddle"] * step,
        "not_ok": not_ok,
    }


def rollout_speed(controller: Controller, rollouts: int) -> tuple[float, float, int]:
    """``(rollouts/s, actions simulated/s, rollouts that ran every action)`` of blocks-7's
    nominal (servo-planned) plan under ``controller``, in this process. A rollout stops at a
    failing action, so a controller under which the servo's plan fails early runs fewer
    actions per rollout: actions per second is the fair comparison of the physics' speed."""
    servo_problem = replace(load("blocks-7"), controller=SERVO_CONTROLLER)
    actions = plan(servo_problem, semantics="deterministic").actions
    problem = replace(servo_problem, controller=controller)
    runner = Rollouts(problem, actions)
    runner.run(0, 0)  # warm the physics' per-problem cache
    executed = complete = 0
    start = time.perf_counter()
    for i in range(rollouts):
        trace: list = []
        runner.run(0, i, trace)
        executed += len(trace) - 1
        complete += len(trace) - 1 == len(actions)
    elapsed = time.perf_counter() - start
    return rollouts / elapsed, executed / elapsed, complete


def push_speed(controller: Controller, repeats: int) -> float:
    """Pushes per second of blocks-7's nominal plan's pushes, each from the state the servo's
    noise-free execution of the plan reaches before it, under ``controller`` (noise-free)."""
    servo_problem = replace(load("blocks-7"), controller=SERVO_CONTROLLER)
    actions = plan(servo_problem, semantics="deterministic").actions
    state = WorldState(())
    pushes = []
    for action in actions:
        if isinstance(action, Push):
            pushes.append((state, action))
        state = simulate(servo_problem, state, action).state
    problem = replace(servo_problem, controller=controller)
    start = time.perf_counter()
    for _ in range(repeats):
        for before, action in pushes:
            simulate(problem, before, action)
    return repeats * len(pushes) / (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pushes", type=int, default=30, help="pushes per scene")
    parser.add_argument(
        "--kp", default="300,150,600", help="compliant gains to measure (the first: rollout speed)"
    )
    parser.add_argument(
        "--rollouts", type=int, default=40, help="blocks-7 rollouts per controller and round"
    )
    parser.add_argument(
        "--fixed",
        action="store_true",
        help="also measure each gain with its set point fixed at the push's end (the set point "
        "speed 1e9 in/s: reached in the first step), the catapult the moving set point avoids",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seed of the scenes' random draws (friction, densities, approach offsets), "
        "the same for every controller (default: %(default)s)",
    )
    parser.add_argument("--output", type=Path, default=None, help="CSV to write the rows to")
    args = parser.parse_args()
    gains = [float(v) for v in args.kp.split(",") if v]
    controllers = [Controller(kind=ControllerKind.SERVO)] + [
        Controller(kind=ControllerKind.COMPLIANT, kp=kp) for kp in gains
    ]
    if args.fixed:
        controllers += [
            Controller(kind=ControllerKind.COMPLIANT, kp=kp, speed=FIXED_SPEED) for kp in gains
        ]
    rows = []
    for controller in controllers:
        label = controller.kind.value
        if controller.speed == FIXED_SPEED:
            label += " fixed set point"
        row = {"controller": label, "kp": controller.kp}
        if controller.kind is ControllerKind.SERVO:
            row["kp"] = ""
        row.update(measure(controller, args.pushes, args.seed))
        rows.append(row)
        print(
            " ".join(
                f"{k}={v:.3g}" if isinstance(v, float) else f"{k}={v}" for k, v in row.items()
            ),
            flush=True,
        )
    if args.output is not None:
        with args.output.open("w", newline="") as handle:
            writer = csv.DictWriter(handle, fieldnames=FIELDS)
            writer.writeheader()
            writer.writerows(rows)
    if args.rollouts > 0 and gains:
        # Interleaved rounds, medians: the machine's load drifts over a run.
        servo_c = Controller(kind=ControllerKind.SERVO)
        compliant_c = Controller(kind=ControllerKind.COMPLIANT, kp=gains[0])
        rounds = {"servo": [], "compliant": []}
        for _ in range(ROUNDS):
            for label, controller in (("servo", servo_c), ("compliant", compliant_c)):
                per_s, actions_s, complete = rollout_speed(controller, args.rollouts)
                rounds[label].append((per_s, actions_s, complete, push_speed(controller, 2)))
        med = {
            label: [float(np.median([r[i] for r in rows_])) for i in range(4)]
            for label, rows_ in rounds.items()
        }
        for label in ("servo", "compliant"):
            per_s, actions_s, complete, pushes_s = med[label]
            print(
                f"blocks-7 nominal plan, {label}: {per_s:.1f} rollouts/s, {actions_s:.1f} "
                f"actions/s ({complete:g} of {args.rollouts} rollouts ran every action), "
                f"{pushes_s:.1f} noise-free pushes/s"
            )
        pairs = list(zip(rounds["compliant"], rounds["servo"], strict=True))
        ratios = [float(np.median([c[i] / v[i] for c, v in pairs])) for i in (0, 1, 3)]
        print(
            f"ratio compliant kp={gains[0]:g} / servo, one process, median of {ROUNDS} "
            f"interleaved rounds: rollouts/s {ratios[0]:.2f}, actions/s {ratios[1]:.2f}, "
            f"pushes/s {ratios[2]:.2f}"
        )


if __name__ == "__main__":
    main()
