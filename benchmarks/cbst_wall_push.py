"""Where a push to the wall sends the paddle, and how often the train buckles: CBST's training
scenes under the push rules of ``GenerationSettings.wall_push``.

Usage::

    python benchmarks/cbst_wall_push.py [--examples 200] [--rollouts 100] [--seed 0]
        [--controller compliant] [--rules wall,uniform,planner]

Every rule pushes the same examples (``arrange_up.cbst.data.generate_example``: the scenes,
states, noise and paddle poses are the same for every rule; only the commanded distance
differs):

* ``wall``: the paddle's front sent to the wall, a whole train length beyond where it stops
  (the planner's push to a wall without ``compressed_wall_pushes``): the compliant PD's error
  stays at that length, so it presses the train with the full force clip;
* ``uniform``: sent uniformly between just past the compressed train and the wall (the data of
  the shipped models);
* ``planner``: sent past the compressed train by ``arrange_up.planning.stall.wall_overdrive``
  (the worst-case stall of the train, the paddle's pose uncertainty along the push and a
  margin): CBST's push to the wall.

Printed per rule: the rows (one per block) whose largest overshoot of its ``x_max`` exceeds
``BUCKLE_LIMIT`` (a block squeezed out of the train: *buckled*, what the model card counts),
the examples with a buckled row, the examples not at rest, and per train length the median
and 90th percentile of the targets ``dx`` (in), ``dy`` (in), ``dθ`` (deg), and the share of
rows whose outcome lies inside the model's training domain (``dx / 2`` and ``dy`` at most
0.4 in, ``dθ`` at most 15°: a later push of that block can be predicted).
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

import numpy as np

from arrange_up.cbst.data import COMPLIANT, DEFAULT_GENERATION, SERVO, generate_example
from arrange_up.cbst.features import BUCKLE_LIMIT


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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--examples", type=int, default=200)
    parser.add_argument("--rollouts", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--controller", choices=("compliant", "servo"), default="compliant")
    parser.add_argument("--rules", default="wall,uniform,planner")
    args = parser.parse_args()
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
