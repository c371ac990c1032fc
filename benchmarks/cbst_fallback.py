"""Compliant CBST with its simulated fallback: what it plans, at what cost, how reliably.

Usage::

    python benchmarks/cbst_fallback.py [--problems blocks-2,blocks-3,...] [--rollouts 1000]
        [--models compliant,path/to/other.json] [--fallback-particles N] [--place-rings on|off]

Plans each shipped problem under its own (compliant) controller with ``semantics="cbst"``
(the shipped model, or each of ``--models`` in turn; seed 0, one worker, the goal agenda, no
validation) and prints one row per problem and model: status, nodes expanded, the search's
CPU seconds (``time.process_time`` of this process, where CBST and its fallback run), the
push transitions that fell back to the physics of all asked for, and the plan's reliability
on ``--rollouts`` rollouts (seed 0, one worker, in this process). Written for issue 33's
targets: see docs/cbst.md, "The simulated fallback".

Two variants measure the choices the planner makes for compliant CBST:
``--fallback-particles N`` draws N states per fallen-back push instead of
:data:`~arrange_up.transitions.cbst.FALLBACK_PARTICLES`' count, and ``--place-rings on`` offers
the place rings that the fallback's semantics turns off (``off``, the default, keeps the
planner's choice).
"""

from __future__ import annotations

import argparse
import itertools
import time

from arrange_up.evaluation.evaluate import evaluate_plan
from arrange_up.io.domains import load
from arrange_up.model.problem import ControllerKind
from arrange_up.parallel import RunnerConfig
from arrange_up.planning.planner import plan
from arrange_up.transitions import cbst

PROBLEMS = ("blocks-2", "blocks-3", "blocks-4", "blocks-7", "blocks-9", "blocks-9-square")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--problems", default=",".join(PROBLEMS), help="comma-separated names")
    parser.add_argument(
        "--rollouts", type=int, default=1000, help="rollouts per plan (default: %(default)s)"
    )
    parser.add_argument(
        "--models",
        default="",
        help="comma-separated CBST models (shipped names or .json cards); default the shipped",
    )
    parser.add_argument(
        "--fallback-particles",
        type=int,
        default=None,
        help="states per fallen-back push (default: the planner's, "
        f"{cbst.FALLBACK_PARTICLES[ControllerKind.COMPLIANT]})",
    )
    parser.add_argument(
        "--place-rings",
        choices=("on", "off"),
        default="off",
        help="offer the place rings where the fallback answers (default: off, the planner's)",
    )
    args = parser.parse_args()
    if args.fallback_particles is not None:
        cbst.FALLBACK_PARTICLES[ControllerKind.COMPLIANT] = args.fallback_particles
    if args.place_rings == "on":
        _offer_place_rings()
    models = args.models.split(",") if args.models else [None]
    print("problem          status     nodes  CPU s  fallbacks         reliability  model")
    for name, model in itertools.product(args.problems.split(","), models):
        problem = load(name)
        started = time.process_time()
        result = plan(problem, semantics="cbst", model=model, workers=1, validate=0)
        seconds = time.process_time() - started
        fell, pushes = result.fallbacks or (0, 0)
        share = f"{fell}/{pushes} ({fell / pushes:.0%})" if pushes else "-"
        reliability = "-"
        if result.actions is not None:
            score = evaluate_plan(
                problem,
                result.actions,
                rollouts=args.rollouts,
                seed=0,
                runner=RunnerConfig(workers=1),
            )
            reliability = f"{score.successes}/{score.trials}"
        print(
            f"{name:<16} {result.status:<10} "
            f"{result.stats['expanded']:>5} {seconds:>6.1f}  "
            f"{share:<17} {reliability:<12} {model or 'shipped'}",
            flush=True,
        )


def _offer_place_rings() -> None:
    """Make every CBST semantics built from now on offer the place rings."""
    init = cbst.CBSTSemantics.__init__

    def offering(self, *args, **kwargs) -> None:
        init(self, *args, **kwargs)
        self.place_rings = True

    cbst.CBSTSemantics.__init__ = offering  # type: ignore[method-assign]


if __name__ == "__main__":
    main()
