"""Planning under the compliant controller: do nominal plans exist for the shipped problems?

Usage::

    python benchmarks/controller_plans.py [--problems all] [--controllers servo,compliant]
        [--kp 300] [--particles 0,25,50] [--particle-problems blocks-4] [--timeout 600]
        [--max-nodes N]
    python benchmarks/controller_plans.py --follow-servo --problems blocks-9-square
        [--output controller-plans.csv]

For each shipped problem (``--problems``, comma-separated, default every one) and controller,
plans with the deterministic planner (one particle, seed 0) and prints a row: status, nodes
expanded, transitions simulated, plan length, seconds. ``--particles`` adds particle-belief
runs (seed 0) of ``--particle-problems``. CBST is trained on the servo and is not run here.
Every row is appended to the CSV as soon as it is measured.
"""

from __future__ import annotations

import argparse
import csv
import time
from dataclasses import replace
from pathlib import Path

from arrange_up.belief.compiled import compile_problem
from arrange_up.io.domains import domain_names, load
from arrange_up.model.problem import SERVO_CONTROLLER, Controller, ControllerKind
from arrange_up.model.world import Push
from arrange_up.planning.config import PlanConfig
from arrange_up.planning.planner import plan
from arrange_up.planning.task import BeliefTask

FIELDS = [
    "problem",
    "controller",
    "semantics",
    "particles",
    "status",
    "expanded",
    "transitions_simulated",
    "plan_length",
    "seconds",
]


def follow_servo(name: str, kp: float | None) -> None:
    """Whether the compliant search space holds the servo's plan: from the compliant planner's
    initial belief, take at each step the candidate the compliant generator offers that is the
    servo plan's action (a place) or its push from within 0.1 in of the same approach pose and
    angle with the nearest distance, and print each step's heuristic and whether the goal is
    reached."""
    servo = replace(load(name), controller=SERVO_CONTROLLER)
    servo_plan = plan(servo, semantics="deterministic").actions
    controller = Controller(kind=ControllerKind.COMPLIANT)
    if kp is not None:
        controller = replace(controller, kp=kp)
    config = PlanConfig.of(
        semantics="deterministic",
        particles=1,
        seed=0,
        workers=1,
        heuristic="inadmissible",
        dominance=True,
        variety=False,
    )
    task = BeliefTask.build(compile_problem(replace(servo, controller=controller)), config)
    belief = task.initial_belief()
    try:
        for k, action in enumerate(servo_plan):
            edges = list(task.successors(belief))
            if isinstance(action, Push):
                same = [
                    e
                    for e in edges
                    if isinstance(e.action, Push)
                    and abs(e.action.pose[2] - action.pose[2]) < 1e-9
                    and max(abs(e.action.pose[i] - action.pose[i]) for i in (0, 1)) < 0.1
                ]
                same.sort(key=lambda e: abs(e.action.distance - action.distance))
            else:
                same = [e for e in edges if e.action == action]
            child = same[0].make_child() if same else None
            if child is None:
                print(f"{name}: step {k}: the compliant generator offers no {action}")
                return
            h = task.heuristic(child)
            print(f"{name}: step {k}: {same[0].action} (servo: {action}); h {h:.3g}")
            belief = child
        print(f"{name}: the followed plan reaches the goal: {task.is_goal(belief)}")
    finally:
        task.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--problems",
        default="all",
        help="comma-separated shipped problem names, or all for every one (default: %(default)s)",
    )
    parser.add_argument(
        "--controllers",
        default="servo,compliant",
        help="comma-separated controller kinds (servo, compliant) to plan under "
        "(default: %(default)s)",
    )
    parser.add_argument("--kp", type=float, default=None, help="the compliant controller's gain")
    parser.add_argument("--particles", default="0", help="0 is the deterministic planner")
    parser.add_argument(
        "--particle-problems",
        default="blocks-4",
        help="comma-separated problems planned with the nonzero --particles counts "
        "(default: %(default)s)",
    )
    parser.add_argument("--timeout", type=float, default=600.0, help="seconds per plan")
    parser.add_argument(
        "--max-nodes", type=int, default=None, help="node limit (default: each problem's own)"
    )
    parser.add_argument(
        "--output",
        type=Path,
        default=None,
        help="CSV file the rows are written to, each as soon as it is measured; overwritten; "
        "unused with --follow-servo (default: none, print only)",
    )
    parser.add_argument(
        "--follow-servo",
        action="store_true",
        help="instead, follow each problem's servo plan with the compliant generator's nearest "
        "candidates (does the compliant search space hold it?)",
    )
    args = parser.parse_args()
    names = domain_names() if args.problems == "all" else args.problems.split(",")
    if args.follow_servo:
        for name in names:
            follow_servo(name, args.kp)
        return
    runs = []
    for count in (int(v) for v in args.particles.split(",")):
        chosen = names if count == 0 else args.particle_problems.split(",")
        runs += [(name, count) for name in chosen]
    writer = None
    handle = None
    if args.output is not None:
        handle = args.output.open("w", newline="")
        writer = csv.DictWriter(handle, fieldnames=FIELDS)
        writer.writeheader()
    try:
        for name, count in runs:
            for kind in args.controllers.split(","):
                controller = Controller(kind=ControllerKind(kind))
                if args.kp is not None and controller.kind is ControllerKind.COMPLIANT:
                    controller = replace(controller, kp=args.kp)
                problem = replace(load(name), controller=controller)
                semantics = "deterministic" if count == 0 else "particles"
                start = time.perf_counter()
                result = plan(
                    problem,
                    semantics=semantics,
                    particles=max(count, 1),
                    seed=0,
                    timeout=args.timeout,
                    max_nodes=args.max_nodes,
                )
                row = {
                    "problem": name,
                    "controller": kind
                    if controller.kind is ControllerKind.SERVO
                    else f"{kind} kp={controller.kp:g}",
                    "semantics": semantics,
                    "particles": max(count, 1),
                    "status": str(result.status.value),
                    "expanded": result.stats.get("expanded"),
                    "transitions_simulated": result.stats.get("transitions_simulated"),
                    "plan_length": len(result.actions or ()),
                    "seconds": round(time.perf_counter() - start, 2),
                }
                print(" ".join(f"{k}={v}" for k, v in row.items()), flush=True)
                if writer is not None:
                    writer.writerow(row)
                    handle.flush()
    finally:
        if handle is not None:
            handle.close()


if __name__ == "__main__":
    main()
