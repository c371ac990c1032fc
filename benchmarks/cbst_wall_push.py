"""Where a push to the wall sends the paddle, and how often the train buckles: CBST's training
scenes under the push rules of ``GenerationSettings.wall_push``.

Usage::

    python benchmarks/cbst_wall_push.py [--examples 200] [--rollouts 100] [--seed 0]
        [--controller compliant] [--rules wall,uniform,planner]
    python benchmarks/cbst_wall_push.py --tilt

Every rule pushes the same examples (``arrange_up.cbst.data.generate_example``: the scenes,
states, noise and paddle poses are the same for every rule; only the commanded distance
differs):

* ``wall``: the paddle's front sent to the wall, a whole train length beyond where it stops
  (the planner's push to a wall without ``compressed_wall_pushes``): the compliant PD's error
  stays at that length, so it presses the train with the full force clip;
* ``uniform``: sent uniformly between just past the compressed train and the wall (the data of
  the shipped models);
* ``planner``: sent past the compressed train by ``arrange_up.physics.stall.wall_overdrive``
  (the worst-case stall of the train, the paddle's pose uncertainty along the push and a
  margin): CBST's push to the wall.

Printed per rule: the rows (one per block) whose largest overshoot of its ``x_max`` exceeds
``BUCKLE_LIMIT`` (a block squeezed out of the train: *buckled*, what the model card counts),
the examples with a buckled row, the examples not at rest, and per train length the median
and 90th percentile of the targets ``dx`` (in), ``dy`` (in), ``dθ`` (deg), and the share of
rows whose outcome lies inside the model's training domain (``dx / 2`` and ``dy`` at most
0.4 in, ``dθ`` at most 15°: a later push of that block can be predicted).

``--tilt`` measures instead why a block pushed to the wall ends turned: one block at 0, 5, 10
and 15°, the paddle centred on it or 0.5 in to either side, friction 0.25, 0.4 and 0.55
(densities at the middle of their ranges), pushed by the ``planner`` rule (no pose
uncertainty) and with its set point 1 in past the compressed block, under each controller.
Printed: the largest and mean final ``|θ|`` of the block (in its 90° period) and the largest
final ``|θ|`` of the paddle from its commanded angle (deg). ``--wrist 1,4,16`` adds compliant
controllers whose wrist is that many times stiffer and stronger than the default (``kp_angle``
and the torque clip both scaled: ``Kp r^2`` and ``force r`` are the defaults, ``r`` the
paddle's radius), to measure how much of the tilt the wrist's compliance is.
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import replace

import numpy as np

from arrange_up.cbst.data import (
    COMPLIANT,
    DEFAULT_GENERATION,
    EAST,
    SERVO,
    _scene,
    _wrap,
    generate_example,
)
from arrange_up.cbst.features import BUCKLE_LIMIT
from arrange_up.model.problem import Controller
from arrange_up.model.world import ActionNoise, Push, WorldState
from arrange_up.physics.settings import push_force
from arrange_up.physics.simulation import DEFAULT_SETTINGS, compliant_gains, simulate
from arrange_up.physics.stall import wall_overdrive


def measure(rule: str, examples: int, rollouts: int, seed: int, controller) -> dict:
    settings = replace(DEFAULT_GENERATION, controller=controller, wall_push=rule)
    domain = settings.domain
    started = time.process_time()
    records = [generate_example(i, seed, rollouts, settings) for i in range(examples)]
    seconds = time.process_time() - started
    rows = [
        (record["blocks"], target, over)
        for record in records
        for target, over in zip(record["targets"], record["overshoot"], strict=True)
    ]
    n = np.array([r[0] for r in rows])
    y = np.array([r[1] for r in rows]).reshape(-1, 4)
    over = np.array([r[2] for r in rows])
    inside = (
        (y[:, 0] / 2 <= domain.block_half[0])
        & (y[:, 1] <= domain.block_half[1])
        & (y[:, 2] <= domain.block_half[2])
    )
    return {
        "rule": rule,
        "rows": len(rows),
        "buckled_rows": int(np.sum(over > BUCKLE_LIMIT)),
        "buckled_examples": sum(
            any(o > BUCKLE_LIMIT for o in record["overshoot"]) for record in records
        ),
        "invalid_examples": sum(not record["valid"] for record in records),
        "seconds": seconds,
        "n": n,
        "y": y,
        "over": over,
        "inside": inside,
    }


def stiff_wrist(scale: float) -> Controller:
    """The default compliant controller with its wrist ``scale`` times as stiff and as strong
    (``kp_angle`` and the torque clip at ``scale`` times their defaults in the CBST scene)."""
    problem = _scene(DEFAULT_GENERATION)
    radius = problem.object("paddle").shape.radius
    # the physics' own defaults; the angle gain and torque clip do not depend on the paddle's
    # mass and moment (they set only the damping, not read here)
    gains = compliant_gains(COMPLIANT, DEFAULT_SETTINGS, 1.0, 1.0, radius, push_force(problem))
    return replace(COMPLIANT, kp_angle=scale * gains.kp_angle, torque=scale * gains.torque)


def tilt(wrists: tuple[float, ...] = ()) -> None:
    """The ``--tilt`` measurement (module docstring), with the stiffer wrists ``wrists``."""
    controllers = [("compliant", COMPLIANT), ("servo", SERVO)]
    controllers += [(f"wrist x{w:g}", stiff_wrist(w)) for w in wrists]
    for name, controller in controllers:
        settings = replace(DEFAULT_GENERATION, controller=controller)
        problem = _scene(settings)
        d = settings.block_size
        wall = settings.table[0]
        middle = 0.5 * settings.table[1]
        planner = wall_overdrive(controller, settings.friction, settings.part_density, d * d, 0.0)
        for label, over in (("planner", planner), ("1 in", 1.0)):
            if over is None:
                continue  # the servo's planner pushes go to the wall
            for start_angle in (0, 5, 10, 15):
                block, paddle = [], []
                for friction in (0.25, 0.4, 0.55):
                    for offset in (-0.5, 0.0, 0.5):
                        state = WorldState(
                            (("b0", (wall - 1.5 * d, middle, math.radians(start_angle))),)
                        )
                        start = wall - 2.8 * d
                        front = wall - d + over
                        push = Push("paddle", (start, middle + offset, EAST), front - start - 0.075)
                        noise = ActionNoise((0.0, 0.0, 0.0), friction, 0.125, 0.4)
                        outcome = simulate(problem, state, push, noise)
                        theta = outcome.state.as_dict()["b0"][2]
                        block.append(abs(math.degrees(_wrap(np.array(theta), 0.5 * math.pi))))
                        paddle.append(abs(math.degrees(outcome.manipulator_pose[2] - EAST)))
                print(
                    f"{name:>9}, set point {label} past the block, start {start_angle:2d} deg: "
                    f"block |theta| max {max(block):.2f} mean {np.mean(block):.2f} deg; "
                    f"paddle |theta| max {max(paddle):.2f} deg"
                )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--examples",
        type=int,
        default=200,
        help="training examples (scenes) pushed under each rule (default: %(default)s)",
    )
    parser.add_argument(
        "--rollouts",
        type=int,
        default=100,
        help="simulated rollouts per example (default: %(default)s)",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seed of the examples, the same for every rule (default: %(default)s)",
    )
    parser.add_argument(
        "--controller",
        choices=("compliant", "servo"),
        default="compliant",
        help="controller driving the paddle in every rollout; --tilt runs both "
        "(default: %(default)s)",
    )
    parser.add_argument(
        "--rules",
        default="wall,uniform,planner",
        help="comma-separated push rules to measure, from wall, uniform and planner "
        "(default: %(default)s)",
    )
    parser.add_argument("--tilt", action="store_true", help="the tilt measurement instead")
    parser.add_argument(
        "--wrist",
        default="",
        metavar="SCALES",
        help="with --tilt: comma-separated multiples of the compliant wrist's default "
        "stiffness and torque clip to measure as well (default: none)",
    )
    args = parser.parse_args()
    if args.tilt:
        tilt(tuple(float(w) for w in args.wrist.split(",") if w))
        return
    controller = COMPLIANT if args.controller == "compliant" else SERVO
    print(
        f"{args.examples} examples (seed {args.seed}) x {args.rollouts} rollouts, "
        f"{args.controller} controller; buckled: overshoot > {BUCKLE_LIMIT} in"
    )
    for rule in args.rules.split(","):
        m = measure(rule, args.examples, args.rollouts, args.seed, controller)
        print(
            f"{rule:>8}: buckled rows {m['buckled_rows']}/{m['rows']} "
            f"({100 * m['buckled_rows'] / m['rows']:.1f}%), examples with a buckled row "
            f"{m['buckled_examples']}/{args.examples}, not at rest {m['invalid_examples']}; "
            f"outcome inside the domain {100 * np.mean(m['inside']):.1f}% of rows; "
            f"{m['seconds']:.0f} CPU-s"
        )
        for k in sorted(set(m["n"].tolist())):
            sel = m["n"] == k
            y = m["y"][sel]
            q = {
                name: (np.median(y[:, j]), np.percentile(y[:, j], 90))
                for j, name in enumerate(("dx", "dy", "dth"))
            }
            print(
                f"{'':>10}{k} block(s): {int(sel.sum())} rows, buckled "
                f"{int(np.sum(m['over'][sel] > BUCKLE_LIMIT))}; median / p90 "
                f"dx {q['dx'][0]:.3f} / {q['dx'][1]:.3f} in, "
                f"dy {q['dy'][0]:.3f} / {q['dy'][1]:.3f} in, "
                f"dth {q['dth'][0]:.1f} / {q['dth'][1]:.1f} deg; inside the domain "
                f"{100 * np.mean(m['inside'][sel]):.0f}%"
            )


if __name__ == "__main__":
    main()
