"""Speed benchmarks of the building blocks (``arrange-up bench physics``).

:func:`bench_physics` measures full push simulations (fresh space, settle, drive, rest,
lift-off; :func:`arrange_up.physics.simulation.simulate`) per second at the default settings (dt
1/240 s,
10 iterations) on three scenes built in code, named after the speed table of
``shared/notes/physics.md`` (whose exact layouts are not recorded):

* ``1 block``: one 1-inch block pushed 2 in across the open table;
* ``3-block chain``: three blocks in a row pushed into the right wall (the paddle is commanded
  3 in and stalls after about 1.5 in);
* ``7-block chain``: seven blocks in a row pushed into the right wall likewise.

All on the thesis's 10 x 5 in board with walls, with its 2.5 x 0.15 in paddle. Every push
differs: friction in [0.25, 0.55], part density in [0.1, 0.15], manipulator density in
[0.35, 0.45], approach pose noise of +-0.02 in and +-0.01 rad, and each block's initial pose
jittered by +-0.01 in and +-0.01 rad (blocks stand 0.05 in apart, so nothing overlaps).

With more than one worker the pushes are split evenly over the project's loky process pool that is
started and warmed up (imports, first push) before the clock starts; its start-up time is
reported separately as ``startup_seconds``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from fractions import Fraction

import numpy as np

from arrange_up.model.problem import (
    ArrangementProblem,
    Goal,
    ObjectKind,
    ObjectSpec,
    Shape,
    Table,
    Uncertainty,
)
from arrange_up.model.world import ActionNoise, Push, WorldState, draw_noise
from arrange_up.parallel import check_workers, local_executor
from arrange_up.physics.settings import SERVO_VALUES
from arrange_up.physics.simulation import (
    DEFAULT_SETTINGS,
    PhysicsSettings,
    SimulationStatus,
    simulate,
)

SCENES: tuple[str, ...] = ("1 block", "3-block chain", "7-block chain")

_TABLE = (10.0, 5.0)
_BLOCK = 1.0
_PADDLE = (2.5, 0.15)
_GAP = 0.05  # between neighbouring blocks
_PADDLE_GAP = 0.1  # between the paddle and the first block
_JITTER = (0.01, 0.01, 0.01)  # initial pose noise of each block (in, in, rad)
_UNCERTAINTY = Uncertainty(
    place=(0.0, 0.0, 0.0),
    push=(0.02, 0.02, 0.01),
    friction=(0.25, 0.55),
    part_density=(0.1, 0.15),
    manipulator_density=(0.35, 0.45),
)
#: scene -> (number of blocks, x of the first block's centre, commanded push distance)
_LAYOUT: dict[str, tuple[int, float, float]] = {
    "1 block": (1, 3.0, 2.0),
    "3-block chain": (3, 6.0, 3.0),
    "7-block chain": (7, 2.0, 2.5),
}


def _box(width: float, height: float) -> Shape:
    w, h = width / 2.0, height / 2.0
    return Shape(parts=(((-w, -h), (w, -h), (w, h), (-w, h)),), box=(width, height))


def scene(name: str) -> tuple[ArrangementProblem, WorldState, Push]:
    """The problem, nominal state and push of one benchmark scene."""
    if name not in _LAYOUT:
        raise ValueError(f"unknown scene {name!r}; expected one of {', '.join(SCENES)}")
    count, x0, distance = _LAYOUT[name]
    y = _TABLE[1] / 2.0
    blocks = [ObjectSpec(f"block{i}", ObjectKind.PART, _box(_BLOCK, _BLOCK)) for i in range(count)]
    paddle = ObjectSpec("paddle", ObjectKind.MANIPULATOR, _box(*_PADDLE))
    problem = ArrangementProblem(
        name=f"bench {name}",
        table=Table(_TABLE),
        objects=(*blocks, paddle),
        initial=(),
        goal=Goal(targets=(), tolerance=(0.1, 0.1, None)),
        uncertainty=_UNCERTAINTY,
    )
    poses = {spec.name: (x0 + i * (_BLOCK + _GAP), y, 0.0) for i, spec in enumerate(blocks)}
    state = WorldState.from_mapping(problem, poses)
    # a 2.5 x 0.15 paddle pushes along its +y; theta = -pi/2 turns that into +x
    approach = (x0 - _BLOCK / 2.0 - _PADDLE[1] / 2.0 - _PADDLE_GAP, y, -math.pi / 2.0)
    return problem, state, Push("paddle", approach, distance)


def _tasks(
    problem: ArrangementProblem, state: WorldState, push: Push, n: int, rng: np.random.Generator
) -> list[tuple[WorldState, ActionNoise]]:
    tasks = []
    jitter = np.asarray(_JITTER)
    for _ in range(n):
        poses = tuple(
            (name, tuple(float(v) for v in np.asarray(pose) + rng.uniform(-1, 1, 3) * jitter))
            for name, pose in state.poses
        )
        tasks.append((WorldState(poses), draw_noise(problem, push, rng)))  # type: ignore[arg-type]
    return tasks


def _run_chunk(
    problem: ArrangementProblem, push: Push, tasks: Sequence[tuple[WorldState, ActionNoise]]
) -> tuple[int, int, float]:
    """Simulate pushes; (not-at-rest count, other not-OK count, total simulated time)."""
    not_at_rest = other = 0
    sim_time = 0.0
    for state, noise in tasks:
        outcome = simulate(problem, state, push, noise)
        sim_time += outcome.sim_time
        if outcome.status is SimulationStatus.NOT_AT_REST:
            not_at_rest += 1
        elif not outcome.ok:
            other += 1
    return not_at_rest, other, sim_time


def _warm(problem: ArrangementProblem, push: Push, tasks, pause: float) -> int:
    _run_chunk(problem, push, tasks)
    time.sleep(pause)  # hold this worker so the next warm-up task goes to another one
    return os.getpid()


def bench_physics(
    n_pushes: int = 200,
    workers: tuple[int, ...] = (1, 2),
    seed: int = 0,
    progress: Callable[[str], None] | None = None,
) -> list[dict]:
    """Push rollouts per second for each scene and worker count.

    Returns one row per (scene, workers): ``scene``, ``workers``, ``pushes``, ``seconds`` (wall
    time of the pushes, pool start-up excluded), ``pushes_per_second``, ``ms_per_push`` (wall
    time per push, so with 2 workers about half the time of one push), ``not_at_rest`` (pushes
    that hit the simulated-time cap), ``not_ok`` (other non-OK outcomes),
    ``mean_sim_time`` (simulated seconds per push) and ``startup_seconds`` (starting and
    warming the pool; 0 for one worker). ``progress`` is called with a line of text before each
    measurement. Every worker count simulates the same pushes.
    """
    if n_pushes < 1:
        raise ValueError("n_pushes must be at least 1")
    if not workers or any(w < 1 for w in workers):
        raise ValueError("workers must be a non-empty tuple of counts >= 1")
    for count in workers:  # all refused before the first measurement, not after it
        check_workers(count)
    rows: list[dict] = []
    rng = np.random.default_rng(seed)
    scenes = []
    for name in SCENES:
        problem, state, push = scene(name)
        scenes.append((name, problem, push, _tasks(problem, state, push, n_pushes, rng)))

    for count in workers:
        executor = None
        startup = 0.0
        if count > 1:
            # The project's shared process pool (arrange_up.parallel): planning and evaluation
            # use the same one, and mixing it with a separate joblib.Parallel pool breaks loky.
            if progress:
                progress(f"starting a pool of {count} worker processes")
            t0 = time.perf_counter()
            executor = local_executor(count)
            _, problem, push, tasks = scenes[0]
            warm = [executor.submit(_warm, problem, push, tasks[:2], 0.2) for _ in range(count)]
            for future in warm:
                future.result()
            startup = time.perf_counter() - t0
        for name, problem, push, tasks in scenes:
            if progress:
                progress(f"{name}: {len(tasks)} pushes on {count} worker(s)")
            if executor is None:
                _run_chunk(problem, push, tasks[:2])  # warm this process's caches
                t0 = time.perf_counter()
                results = [_run_chunk(problem, push, tasks)]
                seconds = time.perf_counter() - t0
            else:
                bounds = np.linspace(0, len(tasks), count + 1).round().astype(int)
                chunks = [tasks[a:b] for a, b in zip(bounds[:-1], bounds[1:], strict=True)]
                t0 = time.perf_counter()
                futures = [
                    executor.submit(_run_chunk, problem, push, chunk) for chunk in chunks if chunk
                ]
                results = [future.result() for future in futures]
                seconds = time.perf_counter() - t0
            pushes = len(tasks)
            rows.append(
                {
                    "scene": name,
                    "workers": count,
                    "pushes": pushes,
                    "seconds": seconds,
                    "pushes_per_second": pushes / seconds,
                    "ms_per_push": 1000.0 * seconds / pushes,
                    "not_at_rest": sum(r[0] for r in results),
                    "not_ok": sum(r[1] for r in results),
                    "mean_sim_time": sum(r[2] for r in results) / pushes,
                    "startup_seconds": startup,
                }
            )
    return rows


def compare_settings(
    settings: PhysicsSettings,
    reference: PhysicsSettings,
    n_pushes: int = 30,
    seed: int = 0,
) -> list[dict]:
    """How far the final poses under ``settings`` are from those under ``reference``, on the
    same noisy pushes of each scene (the tasks :func:`bench_physics` draws).

    One row per scene: ``scene``, ``pushes``, ``median`` and ``max`` distance (in) between a
    block's final centre in the two runs (over every block of every push), ``steps`` and
    ``reference_steps`` (mean physics steps per push), ``not_ok`` and ``reference_not_ok``
    (pushes whose outcome is not ``OK``).
    """
    rng = np.random.default_rng(seed)
    rows = []
    for name in SCENES:
        problem, state, push = scene(name)
        distances: list[float] = []
        steps = [0, 0]
        not_ok = [0, 0]
        for start, noise in _tasks(problem, state, push, n_pushes, rng):
            runs = [simulate(problem, start, push, noise, s) for s in (settings, reference)]
            for k, outcome in enumerate(runs):
                steps[k] += outcome.steps
                not_ok[k] += not outcome.ok
            for (_, a), (_, b) in zip(runs[0].state.poses, runs[1].state.poses, strict=True):
                distances.append(math.hypot(a[0] - b[0], a[1] - b[1]))
        rows.append(
            {
                "scene": name,
                "pushes": n_pushes,
                "median": float(np.median(distances)),
                "max": max(distances),
                "steps": steps[0] / n_pushes,
                "reference_steps": steps[1] / n_pushes,
                "not_ok": not_ok[0],
                "reference_not_ok": not_ok[1],
            }
        )
    return rows


def _settings_of(assignments: Sequence[str]) -> PhysicsSettings:
    """``PhysicsSettings`` with ``KEY=VALUE`` overrides (values as fractions: ``dt=1/960``) of
    the settings before they were chosen per controller (``SERVO_VALUES`` for both
    controllers), which the comparisons of ``docs/design/physics.md`` were measured against."""
    changes: dict[str, float | int] = {}
    for item in assignments:
        key, _, value = item.partition("=")
        number = Fraction(value)
        changes[key] = (
            int(number) if number.denominator == 1 and "." not in value else float(number)
        )
    return replace(DEFAULT_SETTINGS, **{**SERVO_VALUES, **changes})


def format_rows(rows: Sequence[dict]) -> str:
    """The rows as a plain-text table."""
    lines = [
        f"{'scene':<16} {'workers':>7} {'pushes':>7} {'seconds':>8} {'pushes/s':>9} "
        f"{'ms/push':>8} {'not at rest':>11} {'sim s/push':>10} {'startup s':>9}"
    ]
    for row in rows:
        lines.append(
            f"{row['scene']:<16} {row['workers']:>7} {row['pushes']:>7} "
            f"{row['seconds']:>8.2f} {row['pushes_per_second']:>9.0f} "
            f"{row['ms_per_push']:>8.2f} {row['not_at_rest']:>11} "
            f"{row['mean_sim_time']:>10.2f} {row['startup_seconds']:>9.2f}"
        )
    return "\n".join(lines)


if __name__ == "__main__":  # pragma: no cover - quick manual runs
    parser = argparse.ArgumentParser(description="push rollouts per second")
    parser.add_argument("--pushes", type=int, default=200)
    parser.add_argument("--workers", default="1,2")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument(
        "--compare",
        nargs="*",
        metavar="KEY=VALUE",
        help="instead of timing: final poses under these settings against --reference's "
        "(both overrides of the settings before they were chosen per controller)",
    )
    parser.add_argument("--reference", nargs="*", metavar="KEY=VALUE", default=[])
    args = parser.parse_args()
    if args.compare is not None:
        tested, reference = _settings_of(args.compare), _settings_of(args.reference)
        for row in compare_settings(tested, reference, args.pushes, args.seed):
            print(
                f"{row['scene']:<16} median {row['median']:.4f} in, max {row['max']:.4f} in; "
                f"steps {row['steps']:.0f} vs {row['reference_steps']:.0f}; "
                f"not ok {row['not_ok']} vs {row['reference_not_ok']}"
            )
        sys.exit(0)
    result = bench_physics(
        n_pushes=args.pushes,
        workers=tuple(int(w) for w in args.workers.split(",")),
        seed=args.seed,
        progress=lambda msg: print(msg, file=sys.stderr),
    )
    print(format_rows(result))
