"""How reliable is a plan? Monte Carlo rollouts under the problem's full noise.

:func:`evaluate_plan` executes a plan open-loop many times in the physics, each time in a
different world drawn from the problem's uncertainty, and counts how often it reaches the goal::

    from arrange_up.io.domains import load
    from arrange_up.evaluation.evaluate import evaluate_plan
    from arrange_up.io.planfile import read_plan

    problem = load("blocks-2")
    actions, _ = read_plan("blocks-2.plan.json", problem)
    result = evaluate_plan(problem, actions, rollouts=1000, seed=0)
    result.rate, result.interval          # e.g. 0.41, (0.38, 0.44)

The evaluation's parts, one concern per module (every public name is also importable from
here, as before the split):

* :mod:`arrange_up.evaluation.rollouts`: one rollout (what it draws, in which order, and when it
  fails), :func:`simulate_rollout`, :func:`trace_rollout`;
* :mod:`arrange_up.evaluation.outcomes`: a rollout's :class:`RolloutRecord` and
  :class:`Failure`, the failure kinds;
* :mod:`arrange_up.evaluation.reliability`: the :class:`Reliability`, its Wilson interval
  (:func:`wilson_interval`) and the :class:`FailureBreakdown`;
* :mod:`arrange_up.evaluation.records`: the resumable record file (``record=PATH``).

This module runs the rollouts of an evaluation (in this process, on local worker processes or
on Dask) and gathers them.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from functools import partial
from pathlib import Path

from arrange_up.counts import check_count
from arrange_up.evaluation.outcomes import (
    RolloutRecord,
)
from arrange_up.evaluation.records import (
    RecordFile,
    plan_hash,
    record_header,
)
from arrange_up.evaluation.reliability import (
    EvaluationProgress,
    FailureBreakdown,
    ProgressCallback,
    Reliability,
)
from arrange_up.evaluation.rollouts import (
    RolloutContext,
    check_landing,
    rollout_task,
)
from arrange_up.model.problem import ArrangementProblem, ObjectKind, problem_hash
from arrange_up.model.world import Action, Pick, Place, Push
from arrange_up.parallel import RunnerConfig, auto_chunksize
from arrange_up.physics.simulation import DEFAULT_SETTINGS

__all__ = ["MAX_ROLLOUTS", "evaluate_plan"]

#: The most rollouts one evaluation runs. The to-do is lazy, but every finished rollout's
#: record is kept until the breakdown is counted (a failed one holds about 2 KB), and the
#: Wilson interval of a million rollouts is already within ±0.1 %: a larger count is a typo,
#: not a wish (docs/design/cli.md, "Rollout counts").
MAX_ROLLOUTS = 1_000_000


def evaluate_plan(
    problem: ArrangementProblem,
    actions: Sequence[Action],
    *,
    rollouts: int = 1000,
    seed: int = 0,
    runner: RunnerConfig | None = None,
    record: str | Path | None = None,
    progress: ProgressCallback | None = None,
    chunksize: int | None = None,
    keep_records: bool = False,
    landing: str = "fail",
    should_stop: Callable[[], bool] | None = None,
) -> Reliability:
    """Estimate how often ``actions`` achieve ``problem``'s goal under its full noise.

    Parameters
    ----------
    rollouts
        Number of rollouts (indices ``0 .. rollouts - 1``), at most :data:`MAX_ROLLOUTS`.
    seed
        Non-negative integer; rollout ``i`` draws from ``default_rng([seed, i])``, so results
        do not depend on ``runner`` or ``chunksize``.
    runner
        Where rollouts run (:class:`arrange_up.parallel.RunnerConfig`): ``"local"`` processes
        (``workers=None``: every core; 1 runs in this process,
        :data:`~arrange_up.parallel.SERIAL`) or ``"dask"`` (a LocalCluster of ``workers``
        processes, or the cluster at the ``scheduler`` address). None: local processes on
        every core.
    record
        A ``.jsonl`` file that every finished rollout is appended to; an existing file of the
        same evaluation is resumed (see :mod:`arrange_up.evaluation.records`).
    progress
        Called with an :class:`EvaluationProgress` once at the start and after every
        rollout; an exception it raises (``KeyboardInterrupt``) stops the evaluation, with
        everything finished so far recorded.
    chunksize
        Rollouts per task (default :func:`arrange_up.parallel.auto_chunksize`: about four
        tasks per worker, at most 25 rollouts each).
    keep_records
        Keep every rollout's record in :attr:`Reliability.records`.
    landing
        ``"fail"`` (a push whose paddle is put down onto a part fails the action) or
        ``"shove"`` (the physics resolves the overlap); see
        :mod:`arrange_up.evaluation.rollouts`. Recorded in the record file's header and in the
        result.
    should_stop
        Polled before the first rollout and after every finished one; once it returns True no
        further rollout is started, and the result covers the rollouts finished so far (its
        ``trials`` is how many, fewer than ``rollouts``; rollouts still running are dropped).
        A caller that passes it compares ``trials`` with ``rollouts`` before calling the
        estimate complete. Planning uses it to hold a time limit while it validates a plan.

    Raises
    ------
    ValueError
        For bad arguments, or a problem whose initial belief cannot be sampled.
    RecordFileError
        For a record file of another evaluation.
    arrange_up.parallel.BackendUnavailableError
        When the backend is missing.
    """
    started = time.perf_counter()
    check_count("rollouts", rollouts, maximum=MAX_ROLLOUTS)
    check_count("seed", seed, minimum=0)
    runner = RunnerConfig(workers=None) if runner is None else runner
    if chunksize is not None:
        check_count("chunksize", chunksize)
    check_landing(landing)
    actions = tuple(actions)
    for action in actions:
        if not isinstance(action, Place | Push | Pick):
            raise ValueError(f"not an action: {action!r}")
    phash, lhash = problem_hash(problem), plan_hash(actions)
    _check_names(problem, actions)

    file = None
    records: dict[int, RolloutRecord] = {}
    if record is not None:
        # The landing rule changes outcomes: a shoving evaluation hashes its settings with it.
        # The settings are hashed as the problem's controller resolves them, so a record file
        # made under other settling or rest values of that controller does not resume.
        settings = DEFAULT_SETTINGS.for_controller(problem.controller.kind)
        physics = settings if landing == "fail" else (settings, landing)
        header = record_header(problem, phash, lhash, len(actions), seed, physics)
        file = RecordFile(Path(record), header)
        records = {i: r for i, r in file.records.items() if i < rollouts}
    resumed = len(records)
    successes = sum(r.success for r in records.values())
    runner_backend, runner_workers = runner.backend, 1
    try:
        # lazy: the runners draw the indices chunk by chunk, so the to-do costs no memory
        # whatever the count (records holds only indices below rollouts: the count is exact)
        todo = (i for i in range(rollouts) if i not in records)
        left = rollouts - resumed
        if progress is not None:
            progress(EvaluationProgress(resumed, rollouts, successes, 0.0, resumed))
        if left and not (should_stop is not None and should_stop()):
            pool = runner.runner()
            runner_workers = pool.workers
            size = chunksize or auto_chunksize(left, pool.workers)
            context = RolloutContext(f"{phash} {lhash} {landing}", problem, actions, seed, landing)
            results = pool.map(partial(rollout_task, context), todo, size)
            for index, result in results:
                records[index] = result
                successes += result.success
                if file is not None:
                    file.write_line(result.to_json())
                if progress is not None:
                    progress(
                        EvaluationProgress(
                            len(records),
                            rollouts,
                            successes,
                            time.perf_counter() - started,
                            resumed,
                        )
                    )
                if should_stop is not None and should_stop():
                    # every runner's map is a generator: closing it cancels its queued chunks
                    results.close()
                    break
    finally:
        if file is not None:
            file.close()

    ordered = [records[i] for i in sorted(records)]
    return Reliability(
        successes=successes,
        trials=len(ordered),
        failures=FailureBreakdown.from_records(ordered),
        seed=seed,
        elapsed=time.perf_counter() - started,
        resumed=resumed,
        backend=runner_backend,
        workers=runner_workers,
        records=tuple(ordered) if keep_records else None,
        landing=landing,
    )


def _check_names(problem: ArrangementProblem, actions: tuple[Action, ...]) -> None:
    """Refuse a plan naming objects the problem does not have (not a rollout failure)."""
    kinds = {spec.name: spec.kind for spec in problem.objects}
    for k, action in enumerate(actions):
        name = action.manipulator if isinstance(action, Push) else action.obj
        if name not in kinds:
            raise ValueError(
                f"action {k}: problem {problem.name!r} has no object {name!r}; the plan is for "
                "another problem"
            )
        if kinds[name] is ObjectKind.OBSTACLE:
            raise ValueError(f"action {k}: {name!r} is an obstacle, which no action can move")
