"""Many closed-loop episodes on the simulated executor, judged and summarised.

Episode ``i`` of a run with ``seed`` runs :class:`~arrange_up.execution.replanning.ClosedLoop`
on a :class:`~arrange_up.execution.executor.SimulatedExecutor` (its world drawn from
``(seed, i)``), then judges the true final state with the goal test: success, or the failure
that ended it in the kinds of :mod:`arrange_up.evaluation.outcomes` (an action that could not
be carried out, or ``goal_missed``). :func:`run_episodes` summarises them: the success rate's
95% Wilson interval and the failures by kind
(:class:`~arrange_up.evaluation.reliability.Reliability`, as ``evaluate`` reports open-loop
plans), replans per episode, planning time per replan, and
the model failures.

With ``record=PATH`` every finished episode is appended to ``PATH`` as one JSON line after a
header that identifies the run (problem and plan hashes, seed, sense, noise scale, settings);
running again with the same file resumes it, as ``evaluate --record`` does: recorded episodes
are read back, not re-run. A file of another run is refused (:class:`RecordFileError`).
"""

from __future__ import annotations

import json
import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from arrange_up.belief.compiled import compile_problem
from arrange_up.counts import is_integer
from arrange_up.evaluation.outcomes import Failure, RolloutRecord
from arrange_up.evaluation.records import RecordFileError, plan_hash, rollout_line_problem
from arrange_up.evaluation.reliability import FailureBreakdown, Reliability
from arrange_up.execution.belief import ModelFailure
from arrange_up.execution.executor import SimulatedExecutor
from arrange_up.execution.observations import Sensor
from arrange_up.execution.replanning import ClosedLoop, ClosedLoopSettings, LoopOutcome, Replan
from arrange_up.io.files import lock_exclusively, numbered_records, recorded_lines
from arrange_up.model.problem import ArrangementProblem, problem_hash
from arrange_up.model.world import Action

__all__ = [
    "EPISODES_FORMAT",
    "ClosedLoopResult",
    "EpisodeRecord",
    "run_episode",
    "run_episodes",
    "sensor_for",
]

EPISODES_FORMAT = "arrange-up-episodes/1"


def sensor_for(problem: ArrangementProblem, sense: str) -> Sensor:
    """The sensor of ``sense`` for ``problem`` (its objects' symmetry periods)."""
    return Sensor(sense, compile_problem(problem).frame.period)


@dataclass(frozen=True)
class EpisodeRecord:
    """One judged episode: ``success`` or the ``failure``; the actions executed, the replans,
    the model failures, and why the loop stopped."""

    episode: int
    success: bool
    failure: Failure | None
    actions: int
    replans: tuple[Replan, ...]
    model_failures: tuple[ModelFailure, ...]
    stopped: str

    def rollout(self) -> RolloutRecord:
        """The episode as a rollout record (for the failure breakdown)."""
        return RolloutRecord(self.episode, self.success, self.failure)

    def to_json(self) -> dict[str, Any]:
        data = self.rollout().to_json()
        data.pop("rollout")
        return {
            "episode": self.episode,
            **data,
            "actions": self.actions,
            "replans": [r.to_json() for r in self.replans],
            "model_failures": [m.to_json() for m in self.model_failures],
            "stopped": self.stopped,
        }

    @classmethod
    def from_json(cls, data: dict[str, Any]) -> EpisodeRecord:
        rollout = RolloutRecord.from_json(
            {"rollout": data["episode"], "success": data["success"], **_failure(data)}
        )
        return cls(
            rollout.index,
            rollout.success,
            rollout.failure,
            int(data["actions"]),
            tuple(Replan.from_json(r) for r in data["replans"]),
            tuple(ModelFailure.from_json(m) for m in data["model_failures"]),
            str(data["stopped"]),
        )


def _failure(data: dict[str, Any]) -> dict[str, Any]:
    return {"failure": data["failure"]} if "failure" in data else {}


def run_episode(
    problem: ArrangementProblem,
    actions: Sequence[Action],
    sense: str,
    settings: ClosedLoopSettings,
    seed: int,
    episode: int,
    *,
    scale: float = 1.0,
    trace: bool = False,
) -> tuple[EpisodeRecord, LoopOutcome, SimulatedExecutor]:
    """Episode ``episode``: the loop on a simulated executor whose noise is ``scale`` times the
    model's, judged on the true final state. Returns the record, the loop's outcome and the
    executor (whose ``trace`` holds the true states)."""
    sensor = sensor_for(problem, sense)
    executor = SimulatedExecutor(
        problem, sensor, seed, episode, scale=scale, landing=settings.landing
    )
    loop = ClosedLoop(problem, actions, sensor, settings, seed)
    outcome = loop.run(executor, episode, trace=trace)
    failure = outcome.failure
    if failure is None:
        failure = executor.rollouts.goal_failure(executor.state)
    record = EpisodeRecord(
        episode,
        failure is None,
        failure,
        len(outcome.executed),
        outcome.replans,
        outcome.model_failures,
        outcome.stopped,
    )
    return record, outcome, executor


@dataclass(frozen=True)
class ClosedLoopResult:
    """The episodes of one run, and their summary."""

    reliability: Reliability
    episodes: tuple[EpisodeRecord, ...]
    sense: str
    scale: float
    settings: ClosedLoopSettings
    resumed: int = 0

    @property
    def replans(self) -> list[Replan]:
        return [r for e in self.episodes for r in e.replans]

    @property
    def mean_replans(self) -> float:
        return statistics.fmean(len(e.replans) for e in self.episodes) if self.episodes else 0.0

    @property
    def median_replan_seconds(self) -> float | None:
        times = [r.seconds for r in self.replans]
        return statistics.median(times) if times else None

    @property
    def model_failures(self) -> int:
        return sum(len(e.model_failures) for e in self.episodes)

    def to_json(self) -> dict[str, Any]:
        times = [r.seconds for r in self.replans]
        solved = sum(r.status == "solved" for r in self.replans)
        return {
            **self.reliability.to_json(),
            "sense": self.sense,
            "noise_scale": self.scale,
            "settings": self.settings.to_json(),
            "resumed": self.resumed,
            "replans": {
                "total": len(times),
                "per_episode": self.mean_replans,
                "solved": solved,
                "adopted": sum(r.adopted is not None for r in self.replans),
                "seconds": {
                    "median": self.median_replan_seconds,
                    "mean": statistics.fmean(times) if times else None,
                    "max": max(times) if times else None,
                },
            },
            "model_failures": {
                "total": self.model_failures,
                "episodes": sum(bool(e.model_failures) for e in self.episodes),
                "unrecovered": sum(
                    not m.recovered for e in self.episodes for m in e.model_failures
                ),
            },
            "stopped": _count(e.stopped for e in self.episodes),
        }


def _count(values: Any) -> dict[str, int]:
    out: dict[str, int] = {}
    for value in values:
        out[value] = out.get(value, 0) + 1
    return dict(sorted(out.items()))


def _header(
    problem: ArrangementProblem,
    actions: Sequence[Action],
    sense: str,
    seed: int,
    scale: float,
    settings: ClosedLoopSettings,
) -> dict[str, Any]:
    return {
        "format": EPISODES_FORMAT,
        "problem": {"name": problem.name, "hash": problem_hash(problem)},
        "plan": {"hash": plan_hash(actions), "actions": len(actions)},
        "seed": seed,
        "sense": sense,
        "noise_scale": scale,
        "settings": settings.to_json(),
    }


def _no_constant(name: str) -> Any:
    """``json.loads``' hook for ``NaN``, ``Infinity`` and ``-Infinity``, which no record holds
    (Python's reader accepts them; ``Infinity`` actions overflowed an ``int``)."""
    raise ValueError(f"{name} is not a number a record holds")


def _episode_problem(data: Any, max_actions: Any) -> str | None:
    """What is wrong with the JSON ``data`` of one episode line, or None: the count of actions
    executed must be within the run's ``max_actions``, and a failed action one of them or the
    one that failed (the same checks as a rollout line's, :func:`rollout_line_problem`)."""
    if not isinstance(data, dict):
        return f"expected a JSON object, got {type(data).__name__}"
    actions = data.get("actions")
    if not is_integer(actions) or not 0 <= actions <= max_actions:
        return (
            f"actions: expected the number of actions executed, 0 to {max_actions}, got {actions!r}"
        )
    rollout = {"rollout": data.get("episode"), "success": data.get("success"), **_failure(data)}
    # the failed action is the one being executed: index `actions` at most
    return rollout_line_problem(
        rollout, actions + 1, f"the {actions} executed or the one that failed"
    )


def _open_record(path: Path, header: dict[str, Any]) -> tuple[Any, dict[int, EpisodeRecord]]:
    """The record file opened for appending and locked, with the episodes it holds."""
    path.parent.mkdir(parents=True, exist_ok=True)
    handle = open(path, "a+b")  # noqa: SIM115 - closed by the caller
    if not lock_exclusively(handle):
        handle.close()
        raise RecordFileError(f"{path}: the record file is in use by another run")
    try:
        # a last line cut off by a killed run is dropped (its episode runs again)
        lines = recorded_lines(
            handle, path, EPISODES_FORMAT, "an arrange-up episode record", RecordFileError
        )
        lines = [line for line in lines if line.strip()]
        if not lines:
            handle.write(json.dumps(header).encode() + b"\n")
            handle.flush()
            return handle, {}
        if json.loads(lines[0]) != json.loads(json.dumps(header)):
            raise RecordFileError(
                f"{path}: the record file belongs to another closed-loop run (its header "
                "differs in the problem, plan, seed, sense, noise scale or settings); use "
                "another file"
            )

        max_actions = header["settings"]["max_actions"]

        def parse(line: bytes, number: int) -> EpisodeRecord:
            try:
                data = json.loads(line, parse_constant=_no_constant)
                problem = _episode_problem(data, max_actions)
                if problem is None:
                    return EpisodeRecord.from_json(data)
            except (ValueError, KeyError, TypeError, OverflowError) as error:
                problem = str(error)
            raise RecordFileError(f"{path}:{number}: not an episode record: {problem}")

        episodes = numbered_records(
            lines, path, parse, lambda r: r.episode, "episode", RecordFileError
        )
    except RecordFileError:
        handle.close()
        raise
    return handle, episodes


def run_episodes(
    problem: ArrangementProblem,
    actions: Sequence[Action],
    *,
    sense: str = "paddle",
    episodes: int = 20,
    seed: int = 0,
    scale: float = 1.0,
    settings: ClosedLoopSettings = ClosedLoopSettings(),  # noqa: B008 - frozen
    record: str | Path | None = None,
    progress: Callable[[EpisodeRecord], None] | None = None,
    on_resume: Callable[[tuple[int, ...]], None] | None = None,
) -> ClosedLoopResult:
    """Run episodes ``0 .. episodes-1`` (module docstring); ``progress`` receives each record
    as it finishes (also those read back from ``record``). Before any episode runs,
    ``on_resume`` receives the numbers of the episodes read back from ``record`` (not run
    again), if there are any."""
    started = time.monotonic()
    handle = None
    done: dict[int, EpisodeRecord] = {}
    if record is not None:
        handle, done = _open_record(
            Path(record), _header(problem, actions, sense, seed, scale, settings)
        )
    read_back = tuple(sorted(i for i in done if i < episodes))
    resumed = len(read_back)
    out: list[EpisodeRecord] = []
    try:
        if read_back and on_resume is not None:
            on_resume(read_back)
        for i in range(episodes):
            found = done.get(i)
            if found is None:
                found, _, _ = run_episode(problem, actions, sense, settings, seed, i, scale=scale)
                if handle is not None:
                    handle.write(json.dumps(found.to_json()).encode() + b"\n")
                    handle.flush()
            out.append(found)
            if progress is not None:
                progress(found)
    finally:
        if handle is not None:
            handle.close()
    successes = sum(e.success for e in out)
    reliability = Reliability(
        successes,
        len(out),
        FailureBreakdown.from_records(e.rollout() for e in out),
        seed,
        elapsed=time.monotonic() - started,
        resumed=resumed,
        landing=settings.landing,
    )
    return ClosedLoopResult(reliability, tuple(out), sense, scale, settings, resumed)
