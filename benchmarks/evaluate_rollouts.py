"""Benchmark of plan evaluation: rollouts per second on 1 and 2 local workers and on Dask.

    python benchmarks/evaluate_rollouts.py                      # plans blocks-7 first (~30 s)
    python benchmarks/evaluate_rollouts.py --plan b7.json  # a plan file of blocks-7
    python benchmarks/evaluate_rollouts.py --no-dask --rollouts 200

Measures, on the same rollouts (same seed), with pool and cluster start-up timed apart:

1. one worker (in this process);
2. two local worker processes (joblib/loky; pool started and warmed first);
3. a Dask LocalCluster of two single-threaded worker processes (started and warmed first),
   through arrange-up's runner (client.submit + as_completed) and, for comparison, through
   joblib's Dask backend (``parallel_config(backend="dask")``) with the same chunks.

Prints wall times, rollouts per second, the speed-up from the second core, the Dask overhead
against local processes, and the success rate with its 95% Wilson interval. Every backend must
give the identical result; the script says so or fails.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from dataclasses import replace
from functools import partial
from pathlib import Path

from joblib import Parallel, delayed, parallel_config

from arrange_up.evaluation.evaluate import evaluate_plan
from arrange_up.evaluation.records import plan_hash
from arrange_up.evaluation.rollouts import RolloutContext, rollout_task
from arrange_up.io.domains import load
from arrange_up.io.planfile import plan_document, read_plan, write_json_atomic
from arrange_up.model.problem import problem_hash
from arrange_up.parallel import (
    SERIAL,
    RunnerConfig,
    _apply_chunk,
    _chunks,
    auto_chunksize,
    get_runner,
)
from arrange_up.planning.planner import plan


def _plan(problem_name: str, max_nodes: int | None) -> Path:
    problem = load(problem_name)
    t0 = time.perf_counter()
    result = plan(problem, semantics="deterministic", seed=0, max_nodes=max_nodes)
    print(
        f"planned {problem_name} (deterministic): {result.status} in "
        f"{time.perf_counter() - t0:.1f} s"
    )
    if not result.solved:
        sys.exit(f"no plan for {problem_name}; try --max-nodes 20000 or another problem")
    path = Path(tempfile.mkdtemp()) / f"{problem_name}.plan.json"
    doc = plan_document(
        problem,
        result.actions,
        status=result.status,
        semantics="deterministic",
        seed=0,
        search=result.stats,
    )
    write_json_atomic(path, doc)
    return path


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--problem",
        default="blocks-7",
        help="shipped problem whose plan is evaluated; planned first unless --plan is given "
        "(default: %(default)s)",
    )
    parser.add_argument("--plan", default=None, help="plan file (default: plan it first)")
    parser.add_argument(
        "--rollouts",
        type=int,
        default=1000,
        help="rollouts evaluated on each backend (default: %(default)s)",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seed of the rollouts, the same on every backend (default: %(default)s)",
    )
    parser.add_argument(
        "--workers",
        type=int,
        default=2,
        help="worker processes of the local pool and of the Dask cluster (default: %(default)s)",
    )
    parser.add_argument(
        "--max-nodes",
        type=int,
        default=None,
        help="without --plan: node limit of the deterministic planning run "
        "(default: the problem's own, else 5000)",
    )
    parser.add_argument(
        "--no-dask",
        action="store_true",
        help="skip the Dask LocalCluster runs: measure local workers only",
    )
    args = parser.parse_args()

    problem = load(args.problem)
    plan_path = Path(args.plan) if args.plan else _plan(args.problem, args.max_nodes)
    actions, _ = read_plan(plan_path, problem)
    n, w = args.rollouts, args.workers
    print(f"{problem.name}: {len(actions)} actions, {n} rollouts, seed {args.seed}")

    def run(**kw):
        t0 = time.perf_counter()
        result = evaluate_plan(problem, actions, rollouts=n, seed=args.seed, **kw)
        return result, time.perf_counter() - t0

    load_before = os.getloadavg()
    rows = []
    evaluate_plan(problem, actions, rollouts=3, seed=10**6, runner=SERIAL)  # imports, caches
    cpu0 = time.process_time()
    serial, t1 = run(runner=SERIAL, keep_records=True)
    cpu1 = time.process_time() - cpu0
    records = serial.records
    serial = replace(serial, records=None)  # compare results, not kept records
    rows.append(("local, 1 worker (in process)", t1, 0.0))

    t0 = time.perf_counter()
    on_w = RunnerConfig(workers=w)
    evaluate_plan(problem, actions, rollouts=2 * w, seed=10**6, runner=on_w, chunksize=1)
    startup = time.perf_counter() - t0
    local, tw = run(runner=on_w)
    rows.append((f"local, {w} processes (loky)", tw, startup))
    assert local == serial, "local processes disagree with the serial run"

    dask_rows = []
    if not args.no_dask:
        t0 = time.perf_counter()
        runner = get_runner("dask", workers=w)
        on_dask_w = RunnerConfig(workers=w, backend="dask")
        evaluate_plan(problem, actions, rollouts=2 * w, seed=10**6, runner=on_dask_w, chunksize=1)
        startup = time.perf_counter() - t0
        on_dask, td = run(runner=on_dask_w)
        rows.append((f"dask LocalCluster, {w} workers (client)", td, startup))
        assert on_dask == serial, "dask disagrees with the serial run"
        dask_rows.append(td)

        # the same rollouts through joblib's Dask backend, for comparison
        context = RolloutContext(
            f"{problem_hash(problem)} {plan_hash(actions)}", problem, tuple(actions), args.seed
        )
        fn = partial(rollout_task, context)
        size = auto_chunksize(n, runner.workers)
        t0 = time.perf_counter()
        with parallel_config(backend="dask"):
            out = Parallel(n_jobs=-1, batch_size=1, return_as="generator_unordered")(
                delayed(_apply_chunk)(fn, chunk) for chunk in _chunks(range(n), size)
            )
            pairs = sorted((i, r) for chunk in out for i, r in chunk)
        tj = time.perf_counter() - t0
        assert [r for _, r in pairs] == list(records), "joblib-dask disagrees"
        rows.append((f"dask LocalCluster, {w} workers (joblib)", tj, 0.0))

    print()
    print(f"{'backend':<42} {'seconds':>8} {'rollouts/s':>10} {'start-up s':>10}")
    for name, seconds, start in rows:
        print(f"{name:<42} {seconds:>8.2f} {n / seconds:>10.0f} {start:>10.2f}")
    print()
    print(
        f"one worker: {t1:.2f} s wall, {cpu1:.2f} s CPU ({1000 * cpu1 / n:.1f} ms CPU per "
        f"rollout); {w} processes would need {cpu1 / w:.2f} s with {w} free cores"
    )
    print(f"speed-up from {w} processes: {t1 / tw:.2f}x")
    if dask_rows:
        print(
            f"dask overhead against local processes: {dask_rows[0] - tw:+.2f} s "
            f"({100 * (dask_rows[0] / tw - 1):+.0f}%)"
        )
    low, high = serial.interval
    executed = [
        len(actions) if r.success or r.failure.action is None else r.failure.action + 1
        for r in records
    ]
    print(
        f"success rate: {serial.successes}/{serial.trials} = {100 * serial.rate:.1f}% "
        f"(95% Wilson interval {100 * low:.1f}%-{100 * high:.1f}%)"
    )
    print(f"actions simulated per rollout: mean {sum(executed) / n:.1f} of {len(actions)}")
    f = serial.failures
    print(
        f"failures: goal missed {f.goal_missed}, action failed {f.action_failed}, "
        f"not at rest {f.not_at_rest}, off table {f.off_table}"
    )
    load_after = os.getloadavg()
    print(
        f"load average (1 min) before {load_before[0]:.2f}, after {load_after[0]:.2f} on "
        f"{os.cpu_count()} cores: figures are only as good as the machine was idle"
    )
    print("all backends gave the identical result")
    return 0


if __name__ == "__main__":  # the guard matters: Dask's worker processes are spawned
    sys.exit(main())
