"""Which block worlds a compliant CBST model plans, for variants of its training data.

Usage::

    python benchmarks/cbst_compliant_plans.py [--examples 600] [--rollouts 200]
        [--angles 15,25] [--wall-push planner] [--output-dir out/cbst-variants]
    python benchmarks/cbst_compliant_plans.py --angles 15 --rollouts 100 --wrist 1,4 \
        --seed 0 --workers 2 --evaluate 1000

For each training-domain angle (the largest angle half-width of a block's belief in the
training examples, degrees; the shipped models' is 15), trains a compliant model on
``--examples`` examples of ``--rollouts`` rollouts each (seed 0, a 50-example test set of seed
1, one worker) with the pushes to the wall sent by ``--wall-push``, then plans blocks-2, -3, -4
and -7 with it (``plan(..., semantics="cbst", model=...)``, 300 s each) and prints one row per
problem: the variant, status, nodes expanded, plan length and search seconds (and for an
unsolved search the planner's reason line), after a line of the model's 8-fold CV RMSE and
R². A model already trained in its folder is reused.

Written for the question whether the compliant model's refusals of blocks-3 and up come from
the training domain's angle limit (beliefs after a press wider than 15 degrees have no
prediction): see docs/cbst.md. ``--wrist`` trains and plans under compliant controllers whose
wrist is that many times stiffer and stronger than the default (``cbst_wall_push.stiff_wrist``;
the problems are driven by the same controller, so the model's card matches them), for the
question how much of the refusals the wrist's tilt is; ``--evaluate N`` scores every plan found
on N rollouts (seed 0) under that controller.
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import replace
from pathlib import Path

from cbst_wall_push import stiff_wrist  # this folder's: the scripts run from it

from arrange_up.cbst.data import COMPLIANT, GenerationSettings
from arrange_up.cbst.features import Domain
from arrange_up.cbst.model import train_cbst
from arrange_up.evaluation.evaluate import evaluate_plan
from arrange_up.io.domains import load
from arrange_up.parallel import RunnerConfig
from arrange_up.planning.planner import plan

PROBLEMS = ("blocks-2", "blocks-3", "blocks-4", "blocks-7")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--examples",
        type=int,
        default=600,
        help="training examples per model (default: %(default)s)",
    )
    parser.add_argument(
        "--rollouts",
        type=int,
        default=200,
        help="simulated rollouts per training example (default: %(default)s)",
    )
    parser.add_argument("--angles", default="15,25", help="comma-separated degrees")
    parser.add_argument(
        "--wall-push",
        default="planner",
        choices=("uniform", "wall", "planner"),
        help="where the training pushes send the paddle's front: uniform between the "
        "compressed train of blocks and the wall, wall at the wall, planner where CBST's push "
        "to the wall does (default: %(default)s)",
    )
    parser.add_argument(
        "--output-dir",
        type=Path,
        default=Path("out/cbst-variants"),
        metavar="DIR",
        help="folder holding one subfolder per trained model; a model already there is "
        "reused (default: %(default)s)",
    )
    parser.add_argument(
        "--wrist",
        default="1",
        metavar="SCALES",
        help="comma-separated multiples of the compliant wrist's default stiffness and torque "
        "clip, one model each (default: %(default)s, the default controller)",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seed of the training data and the forest; the test set's is seed + 1 "
        "(default: %(default)s)",
    )
    parser.add_argument(
        "--workers",
        type=int,
        default=1,
        help="processes generating the data and evaluating the plans (default: %(default)s)",
    )
    parser.add_argument(
        "--evaluate",
        type=int,
        default=0,
        metavar="N",
        help="rollouts (seed 0) scoring every plan found (default: %(default)s, none)",
    )
    args = parser.parse_args()
    base = GenerationSettings()
    for wrist in (float(w) for w in args.wrist.split(",")):
        controller = COMPLIANT if wrist == 1 else stiff_wrist(wrist)
        for angle in (float(a) for a in args.angles.split(",")):
            variant(args, replace(base, controller=controller), controller, angle, wrist)


def variant(args: argparse.Namespace, base: GenerationSettings, controller, angle, wrist) -> None:
    """Train (or reuse) the model of one variant, then plan (and score) the problems with it."""
    half = (base.domain.block_half[0], base.domain.block_half[1], angle)
    settings = replace(base, wall_push=args.wall_push, domain=Domain(block_half=half))
    name = f"angle{angle:g}-{args.examples}x{args.rollouts}-{args.wall_push}"
    if wrist != 1 or args.seed != 0:  # the folders of the first variants keep their names
        name += f"-wrist{wrist:g}-seed{args.seed}"
    folder = args.output_dir / name
    card_path = folder / "compliant.json"
    if not card_path.is_file():
        started = time.perf_counter()
        train_cbst(
            examples=args.examples,
            rollouts_per_example=args.rollouts,
            seed=args.seed,
            workers=args.workers,
            output_dir=folder,
            controller=controller,
            settings=settings,
            test_examples=50,
            test_seed=args.seed + 1,
            name="compliant",
        )
        print(f"{name}: trained in {time.perf_counter() - started:.0f} s", flush=True)
    scores = json.loads(card_path.read_text())["scores"]
    cv = ", ".join(
        f"{t} {scores['cv_rmse'][t]:.4g} ({scores['cv_r2'][t]:.3f})" for t in scores["cv_rmse"]
    )
    print(f"{name}: 8-fold CV RMSE (R2) {cv}", flush=True)
    for problem_name in PROBLEMS:
        problem = replace(load(problem_name), controller=controller)
        result = plan(problem, semantics="cbst", model=card_path, workers=1, timeout=300)
        print(result_line(f"{name} {problem_name}", problem, result, args), flush=True)


def result_line(label: str, problem, result, args: argparse.Namespace) -> str:
    """One row for a planning ``result`` of ``problem``: status, nodes, plan length, search
    seconds, the planner's reason when unsolved, and with ``args.evaluate`` the plan's score on
    that many rollouts (seed 0, ``args.workers``)."""
    line = (
        f"{label}: {result.status}, {result.stats['expanded']} nodes, "
        f"{len(result.actions or ())} actions, {result.stats['elapsed']:.1f} s"
    )
    if not result.solved:
        line += f" ({result.reason})"
    if args.evaluate and result.actions is not None:
        score = evaluate_plan(
            problem,
            result.actions,
            rollouts=args.evaluate,
            seed=0,
            runner=RunnerConfig(workers=args.workers),
        )
        low, high = score.interval
        line += (
            f"; {score.successes} of {score.trials} rollouts reach the goal "
            f"(Wilson {100 * low:.1f}-{100 * high:.1f} %)"
        )
    return line


if __name__ == "__main__":
    main()
