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

A rollout
=========
Rollout ``i`` draws everything from one generator, ``numpy.random.default_rng([seed, i])``, so
its outcome depends only on ``(seed, i)``: not on the backend, the worker count, the chunking
or the order in which rollouts finish. In that stream, in this order:

1. The initial poses: each object of the initial belief uniformly within its interval
   (``problem.initial``), redrawn until nothing overlaps (rejection sampling,
   :func:`arrange_up.belief.states.sample_initial_particles`).
2. For every action in turn, its noise (:func:`arrange_up.model.world.draw_noise`: place and push
   pose offsets, friction, part and manipulator densities, drawn fresh per action), then the
   action is simulated (:func:`arrange_up.physics.simulation.simulate`).
3. At the end, the goal test (:class:`arrange_up.belief.goals.GoalTest`).

The rollout fails at the first of these (and records which):

* ``action_failed``: the action cannot be applied: the physics refuses it (placing an object
  already on the table, pushing with a manipulator that is on the table, picking an object that
  is not there: the physics' ``ValueError``, whose message is the reason); a push starts with
  shapes overlapping by more than the physics' ``overlap_tolerance`` (0.02 in; the paddle was
  put down on a part); or a place puts its object overlapping another object, a wall or an
  obstacle by more than that tolerance (the physics does not check places).
* ``not_at_rest``: a push's simulation hit its time cap before everything came to rest.
* ``off_table``: an object's centroid ended outside the table (open edges).
* ``goal_missed``: the plan ran through, but at least one goal part misses its tolerance (the
  record says which parts, in which dimensions ``x``, ``y``, ``theta``, by how much beyond the
  tolerance, or ``off table`` when a goal part is not on the table).

The result
==========
A :class:`Reliability`: ``successes`` of ``trials``, ``rate`` and its 95% **Wilson score
interval** (:func:`wilson_interval`). Wilson's interval rather than the normal ("Wald") one:
it stays inside [0, 1] and is not degenerate at 0 or ``trials`` successes (a plan that never
failed in 1000 rollouts gets [0.996, 1], not [1, 1]), and its coverage is close to nominal even
for small counts, which the Wald interval's is not. ``failures`` breaks the failures down by
kind (:class:`FailureBreakdown`).

Recording and resuming
======================
With ``record=PATH`` every finished rollout is appended to ``PATH`` at once as one JSON line
(flushed), after a header line identifying the evaluation (format, problem hash, plan hash,
seed, physics settings). Running again with the same file resumes: rollouts already recorded
are read back, not re-run, and the result is identical to an uninterrupted run's. A file whose
header identifies another evaluation is refused (:class:`RecordFileError`), never mixed. A run
killed halfway keeps every rollout that reached the file; with a process pool a rollout reaches
it when its chunk (a few rollouts, see :mod:`arrange_up.parallel`) comes back. A line cut off by
the kill is dropped on resume. The file is locked while a run writes to it. See
``docs/evaluation.md`` for the line format.
"""

from __future__ import annotations

import hashlib
import json
import math
import time
from collections import Counter
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import IO, Any, NamedTuple

import numpy as np

from arrange_up.model.problem import ArrangementProblem, ObjectKind, problem_hash
from arrange_up.model.world import Action, Pick, Place, Push, WorldState, draw_noise

__all__ = [
    "RECORD_FORMAT",
    "Z95",
    "EvaluationProgress",
    "Failure",
    "FailureBreakdown",
    "GoalMiss",
    "RecordFileError",
    "Reliability",
    "RolloutRecord",
    "evaluate_plan",
    "plan_hash",
    "simulate_rollout",
    "trace_rollout",
    "wilson_interval",
]

RECORD_FORMAT = "arrange-up-rollouts/1"
#: The standard normal quantile of a two-sided 95% interval.
Z95 = 1.959963984540054

GOAL_MISSED = "goal_missed"
ACTION_FAILED = "action_failed"
NOT_AT_REST = "not_at_rest"
OFF_TABLE = "off_table"
FAILURE_KINDS: tuple[str, ...] = (GOAL_MISSED, ACTION_FAILED, NOT_AT_REST, OFF_TABLE)

PUSH_OVERLAP_REASON = "the push started with shapes overlapping"


class RecordFileError(ValueError):
    """A record file that belongs to another evaluation, is corrupt, or is in use."""


# ----------------------------------------------------------------------------------------------
# statistics
# ----------------------------------------------------------------------------------------------
def wilson_interval(successes: int, trials: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval of a binomial proportion (95% with the default ``z``).

    ``(centre ± half) / (1 + z²/n)`` with ``centre = p + z²/2n`` and
    ``half = z sqrt(p(1-p)/n + z²/4n²)``; ``(0, 1)`` when there are no trials.

    >>> [round(v, 4) for v in wilson_interval(1000, 1000)]
    [0.9962, 1.0]
    """
    if trials <= 0:
        return (0.0, 1.0)
    if not 0 <= successes <= trials:
        raise ValueError(f"successes must be within [0, {trials}], got {successes}")
    n = float(trials)
    p = successes / n
    z2 = z * z
    denominator = 1.0 + z2 / n
    centre = (p + z2 / (2.0 * n)) / denominator
    half = z * math.sqrt(p * (1.0 - p) / n + z2 / (4.0 * n * n)) / denominator
    low = 0.0 if successes == 0 else max(0.0, centre - half)
    high = 1.0 if successes == trials else min(1.0, centre + half)
    return (low, high)


# ----------------------------------------------------------------------------------------------
# values
# ----------------------------------------------------------------------------------------------
class GoalMiss(NamedTuple):
    """One goal part's miss at the end of a rollout: the dimensions beyond the tolerance
    (``x``, ``y``, ``theta``, or ``off table``) and the excess per dimension (in, in, rad)."""

    part: str
    dimensions: tuple[str, ...]
    excess: tuple[float, float, float]


@dataclass(frozen=True)
class Failure:
    """Why one rollout failed (see the module docstring for the kinds).

    ``action`` is the 0-based index of the failing action in the plan (``None`` for
    ``goal_missed``); ``reason`` says why an action failed (stable across rollouts, so failures
    can be counted by it), ``detail`` adds this rollout's particulars (an overlap's depth);
    ``objects`` lists what ended off the table; ``misses`` the goal parts that missed.
    """

    kind: str
    action: int | None = None
    reason: str | None = None
    detail: str | None = None
    objects: tuple[str, ...] = ()
    misses: tuple[GoalMiss, ...] = ()

    def to_json(self) -> dict[str, Any]:
        data: dict[str, Any] = {"kind": self.kind}
        if self.action is not None:
            data["action"] = self.action
        if self.reason is not None:
            data["reason"] = self.reason
        if self.detail is not None:
            data["detail"] = self.detail
        if self.objects:
            data["objects"] = list(self.objects)
        if self.misses:
            data["misses"] = [
                {"part": m.part, "dimensions": list(m.dimensions), "excess": list(m.excess)}
                for m in self.misses
            ]
        return data

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> Failure:
        if data.get("kind") not in FAILURE_KINDS:
            raise ValueError(f"unknown failure kind {data.get('kind')!r}")
        return cls(
            kind=data["kind"],
            action=data.get("action"),
            reason=data.get("reason"),
            detail=data.get("detail"),
            objects=tuple(data.get("objects", ())),
            misses=tuple(
                GoalMiss(m["part"], tuple(m["dimensions"]), tuple(m["excess"]))  # type: ignore[arg-type]
                for m in data.get("misses", ())
            ),
        )


@dataclass(frozen=True)
class RolloutRecord:
    """The outcome of rollout ``index``: success, or the :class:`Failure` that ended it."""

    index: int
    success: bool
    failure: Failure | None = None

    def to_json(self) -> dict[str, Any]:
        data: dict[str, Any] = {"rollout": self.index, "success": self.success}
        if self.failure is not None:
            data["failure"] = self.failure.to_json()
        return data

    @classmethod
    def from_json(cls, data: Mapping[str, Any]) -> RolloutRecord:
        index, success = data["rollout"], data["success"]
        if not isinstance(index, int) or isinstance(index, bool) or index < 0:
            raise ValueError(f"rollout: expected a non-negative integer, got {index!r}")
        if not isinstance(success, bool):
            raise ValueError(f"success: expected true or false, got {success!r}")
        failure = data.get("failure")
        if success == (failure is not None):
            raise ValueError("a rollout has a failure exactly when it did not succeed")
        return cls(index, success, None if failure is None else Failure.from_json(failure))


class GoalMissCount(NamedTuple):
    part: str
    dimension: str
    rollouts: int
    worst: float
    """Largest excess beyond the tolerance over those rollouts (in or rad; 0 for off table)."""


class ActionFailureCount(NamedTuple):
    action: int
    reason: str
    rollouts: int


class ActionCount(NamedTuple):
    action: int
    rollouts: int


class OffTableCount(NamedTuple):
    action: int
    object: str
    rollouts: int


@dataclass(frozen=True)
class FailureBreakdown:
    """Failed rollouts counted by kind (see the module docstring).

    ``goal_missed`` etc. count rollouts of each kind; the tuples break them down (sorted by
    action index, then name): per goal part and dimension (a rollout that missed a part in two
    dimensions counts in both), per action and reason, per action, per action and object.
    Action indices are 0-based positions in the plan.
    """

    goal_missed: int = 0
    action_failed: int = 0
    not_at_rest: int = 0
    off_table: int = 0
    goal_misses: tuple[GoalMissCount, ...] = ()
    action_failures: tuple[ActionFailureCount, ...] = ()
    not_at_rest_actions: tuple[ActionCount, ...] = ()
    off_table_actions: tuple[OffTableCount, ...] = ()

    @property
    def total(self) -> int:
        return self.goal_missed + self.action_failed + self.not_at_rest + self.off_table

    @classmethod
    def from_records(cls, records: Iterable[RolloutRecord]) -> FailureBreakdown:
        kinds: Counter[str] = Counter()
        misses: Counter[tuple[str, str]] = Counter()
        worst: dict[tuple[str, str], float] = {}
        failed: Counter[tuple[int, str]] = Counter()
        rest: Counter[int] = Counter()
        off: Counter[tuple[int, str]] = Counter()
        dims = ("x", "y", "theta")
        for record in records:
            f = record.failure
            if f is None:
                continue
            kinds[f.kind] += 1
            if f.kind == GOAL_MISSED:
                for miss in f.misses:
                    for dim in miss.dimensions:
                        key = (miss.part, dim)
                        misses[key] += 1
                        excess = miss.excess[dims.index(dim)] if dim in dims else 0.0
                        worst[key] = max(worst.get(key, 0.0), float(excess))
            elif f.kind == ACTION_FAILED:
                failed[(int(f.action or 0), f.reason or "")] += 1
            elif f.kind == NOT_AT_REST:
                rest[int(f.action or 0)] += 1
            elif f.kind == OFF_TABLE:
                for name in f.objects:
                    off[(int(f.action or 0), name)] += 1
        return cls(
            goal_missed=kinds[GOAL_MISSED],
            action_failed=kinds[ACTION_FAILED],
            not_at_rest=kinds[NOT_AT_REST],
            off_table=kinds[OFF_TABLE],
            goal_misses=tuple(
                GoalMissCount(p, d, n, worst[(p, d)]) for (p, d), n in sorted(misses.items())
            ),
            action_failures=tuple(
                ActionFailureCount(a, r, n) for (a, r), n in sorted(failed.items())
            ),
            not_at_rest_actions=tuple(ActionCount(a, n) for a, n in sorted(rest.items())),
            off_table_actions=tuple(OffTableCount(a, o, n) for (a, o), n in sorted(off.items())),
        )

    def to_json(self) -> dict[str, Any]:
        """Counts for ``--json`` output (excess in inches and radians)."""
        parts: dict[str, dict[str, dict[str, float | int]]] = {}
        for m in self.goal_misses:
            parts.setdefault(m.part, {})[m.dimension] = {"rollouts": m.rollouts, "worst": m.worst}
        return {
            "total": self.total,
            GOAL_MISSED: {"rollouts": self.goal_missed, "parts": parts},
            ACTION_FAILED: {
                "rollouts": self.action_failed,
                "actions": [c._asdict() for c in self.action_failures],
            },
            NOT_AT_REST: {
                "rollouts": self.not_at_rest,
                "actions": [c._asdict() for c in self.not_at_rest_actions],
            },
            OFF_TABLE: {
                "rollouts": self.off_table,
                "actions": [c._asdict() for c in self.off_table_actions],
            },
        }


@dataclass(frozen=True)
class Reliability:
    """The reliability of a plan estimated from ``trials`` rollouts.

    ``rate`` is ``successes / trials`` and ``interval`` its 95% Wilson score interval.
    ``elapsed`` (seconds of this call), ``resumed`` (rollouts read back from a record file),
    ``backend`` and ``workers`` describe the run, not the result: they are left out of ``==``,
    so a resumed evaluation compares equal to an uninterrupted one. ``records`` holds every
    rollout's :class:`RolloutRecord` in index order when asked for (``keep_records=True``).
    """

    successes: int
    trials: int
    failures: FailureBreakdown
    seed: int
    rate: float = field(init=False)
    interval: tuple[float, float] = field(init=False)
    elapsed: float = field(default=0.0, compare=False)
    resumed: int = field(default=0, compare=False)
    backend: str = field(default="local", compare=False)
    workers: int = field(default=1, compare=False)
    records: tuple[RolloutRecord, ...] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "rate", self.successes / self.trials if self.trials else 0.0)
        object.__setattr__(self, "interval", wilson_interval(self.successes, self.trials))

    def to_json(self) -> dict[str, Any]:
        return {
            "successes": self.successes,
            "trials": self.trials,
            "rate": self.rate,
            "interval": list(self.interval),
            "failures": self.failures.to_json(),
            "seed": self.seed,
            "elapsed": self.elapsed,
            "resumed": self.resumed,
            "backend": self.backend,
            "workers": self.workers,
        }


@dataclass(frozen=True)
class EvaluationProgress:
    """What a progress callback is told after each rollout (and once at the start)."""

    done: int
    total: int
    successes: int
    elapsed: float
    resumed: int = 0

    @property
    def rate(self) -> float:
        return self.successes / self.done if self.done else 0.0


ProgressCallback = Callable[[EvaluationProgress], None]


# ----------------------------------------------------------------------------------------------
# one rollout
# ----------------------------------------------------------------------------------------------
def plan_hash(actions: Sequence[Action]) -> str:
    """A content hash of a plan's actions (internal units, exact floats): ``"sha256:<hex>"``."""

    def canonical(action: Action) -> list[Any]:
        if isinstance(action, Place):
            return ["place", action.obj, [float(v) for v in action.pose]]
        if isinstance(action, Push):
            return [
                "push",
                action.manipulator,
                [float(v) for v in action.pose],
                float(action.distance),
            ]
        if isinstance(action, Pick):
            return ["pick", action.obj]
        raise TypeError(f"not an action: {action!r}")

    text = json.dumps([canonical(a) for a in actions], separators=(",", ":"))
    return "sha256:" + hashlib.sha256(text.encode("utf-8")).hexdigest()


class _Prepared:
    """Per-problem helpers of the rollouts, built once per process (see ``_prepared``)."""

    def __init__(self, problem: ArrangementProblem, actions: tuple[Action, ...]) -> None:
        from arrange_up.belief.goals import GoalTest
        from arrange_up.belief.states import AngleFrame
        from arrange_up.geometry.shapes import wall_boxes
        from arrange_up.physics.simulation import DEFAULT_SETTINGS

        self.problem = problem
        self.actions = actions
        self.settings = DEFAULT_SETTINGS
        self.goal = GoalTest(problem)
        self.frame = AngleFrame.of(problem)
        self.parts = {
            spec.name: [np.asarray(part, dtype=float) for part in spec.shape.parts]
            for spec in problem.objects
        }
        self.radius = {spec.name: spec.shape.radius for spec in problem.objects}
        fixed: list[tuple[str, np.ndarray]] = []
        for edge, (x0, y0, x1, y1) in wall_boxes(problem.table.size, problem.table.walls).items():
            fixed.append((f"the {edge} wall", np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])))
        for spec in problem.obstacles:
            if spec.pose is not None:
                for part in self.parts[spec.name]:
                    fixed.append((spec.name, _to_world(part, spec.pose)))
        self.fixed = fixed


_PREPARED: dict[str, _Prepared] = {}


def _prepared(key: str, problem: ArrangementProblem, actions: tuple[Action, ...]) -> _Prepared:
    # Keyed by the problem and plan hashes: a worker receiving the same evaluation's problem
    # again (a fresh unpickled copy per task) reuses the first copy, and with it the physics'
    # per-problem cache.
    hit = _PREPARED.get(key)
    if hit is None:
        if len(_PREPARED) >= 8:
            _PREPARED.pop(next(iter(_PREPARED)))
        hit = _PREPARED[key] = _Prepared(problem, actions)
    return hit


def simulate_rollout(
    problem: ArrangementProblem, actions: Sequence[Action], seed: int, index: int
) -> RolloutRecord:
    """Run rollout ``index`` of an evaluation with ``seed`` (see the module docstring).

    The same ``(seed, index)`` always gives the same record; use it to replay one rollout of
    an evaluation (:func:`trace_rollout` gives its states).
    """
    actions = tuple(actions)
    prep = _Prepared(problem, actions)
    return _rollout(prep, seed, index)


def trace_rollout(
    problem: ArrangementProblem, actions: Sequence[Action], seed: int, index: int
) -> tuple[WorldState, ...]:
    """The world states of rollout ``index`` (the same rollout :func:`evaluate_plan` runs with
    ``seed``): the initial state, then the state after each action, cut short where the
    rollout failed (the failing action's state is not included; a rollout that only missed
    the goal has all ``len(actions) + 1`` states)."""
    states: list[WorldState] = []
    _rollout(_Prepared(problem, tuple(actions)), seed, index, states)
    return tuple(states)


def _rollout(
    prep: _Prepared, seed: int, index: int, trace: list[WorldState] | None = None
) -> RolloutRecord:
    from arrange_up.belief.states import sample_initial_particles
    from arrange_up.physics.simulation import StepStatus, simulate

    problem = prep.problem
    rng = np.random.default_rng([seed, index])
    state = sample_initial_particles(problem, 1, rng, frame=prep.frame).particles[0]
    if trace is not None:
        trace.append(state)
    tolerance = prep.settings.overlap_tolerance
    for k, action in enumerate(prep.actions):
        noise = draw_noise(problem, action, rng)
        try:
            outcome = simulate(problem, state, action, noise, prep.settings)
        except ValueError as error:
            return _failed(index, Failure(ACTION_FAILED, k, str(error)))
        if outcome.status is StepStatus.OVERLAP:
            return _failed(
                index,
                Failure(
                    ACTION_FAILED,
                    k,
                    f"{PUSH_OVERLAP_REASON} (by more than {tolerance:g} in)",
                    f"deepest overlap {outcome.overlap:.4f} in",
                ),
            )
        if outcome.status is StepStatus.NOT_AT_REST:
            return _failed(index, Failure(NOT_AT_REST, k))
        if outcome.status is StepStatus.OFF_TABLE:
            return _failed(index, Failure(OFF_TABLE, k, objects=tuple(outcome.off_table)))
        state = outcome.state
        if isinstance(action, Place):
            other, depth = _placement_overlap(prep, state, action.obj)
            if depth > tolerance:
                return _failed(
                    index,
                    Failure(
                        ACTION_FAILED,
                        k,
                        f"placed overlapping {other} (by more than {tolerance:g} in)",
                        f"overlap {depth:.4f} in",
                    ),
                )
        if trace is not None:
            trace.append(state)
    misses = prep.goal.misses(state)
    if misses:
        return _failed(
            index,
            Failure(
                GOAL_MISSED,
                misses=tuple(
                    GoalMiss(m.part, m.dimensions(), tuple(float(e) for e in m.excess))  # type: ignore[arg-type]
                    for m in misses
                ),
            ),
        )
    return RolloutRecord(index, True)


def _failed(index: int, failure: Failure) -> RolloutRecord:
    return RolloutRecord(index, False, failure)


def _to_world(part: np.ndarray, pose: tuple[float, float, float]) -> np.ndarray:
    x, y, theta = pose
    c, s = math.cos(theta), math.sin(theta)
    out = np.empty_like(part)
    out[:, 0] = part[:, 0] * c - part[:, 1] * s + x
    out[:, 1] = part[:, 0] * s + part[:, 1] * c + y
    return out


def _penetration(a: np.ndarray, b: np.ndarray) -> float:
    """Penetration depth of two convex polygons (separating axis theorem; 0 when apart)."""
    best = math.inf
    for poly in (a, b):
        edges = np.roll(poly, -1, axis=0) - poly
        normals = np.stack([edges[:, 1], -edges[:, 0]], axis=1)
        lengths = np.hypot(normals[:, 0], normals[:, 1])
        normals = normals[lengths > 0] / lengths[lengths > 0, None]
        pa, pb = a @ normals.T, b @ normals.T
        overlap = np.minimum(pa.max(axis=0), pb.max(axis=0)) - np.maximum(
            pa.min(axis=0), pb.min(axis=0)
        )
        smallest = float(overlap.min())
        if smallest <= 0.0:
            return 0.0
        best = min(best, smallest)
    return best


def _placement_overlap(prep: _Prepared, state: WorldState, name: str) -> tuple[str, float]:
    """The deepest overlap of the just placed ``name`` with anything else: (what, depth)."""
    pose = state.pose(name)
    assert pose is not None
    placed = [_to_world(part, pose) for part in prep.parts[name]]
    reach = prep.radius[name]
    worst = ("nothing", 0.0)
    for other, other_pose in state.poses:
        if (
            other == name
            or math.hypot(other_pose[0] - pose[0], other_pose[1] - pose[1])
            > reach + prep.radius[other]
        ):
            continue
        for part in prep.parts[other]:
            world = _to_world(part, other_pose)
            for mine in placed:
                depth = _penetration(mine, world)
                if depth > worst[1]:
                    worst = (other, depth)
    lo = np.array([pose[0] - reach, pose[1] - reach])
    hi = np.array([pose[0] + reach, pose[1] + reach])
    for label, poly in prep.fixed:
        if np.any(poly.max(axis=0) < lo) or np.any(poly.min(axis=0) > hi):
            continue
        for mine in placed:
            depth = _penetration(mine, poly)
            if depth > worst[1]:
                worst = (label, depth)
    return worst


@dataclass(frozen=True)
class _Context:
    """What a worker needs to run rollouts of one evaluation (pickled with each task)."""

    key: str
    problem: ArrangementProblem
    actions: tuple[Action, ...]
    seed: int


def _rollout_task(context: _Context, index: int) -> RolloutRecord:
    prep = _prepared(context.key, context.problem, context.actions)
    return _rollout(prep, context.seed, index)


# ----------------------------------------------------------------------------------------------
# the record file
# ----------------------------------------------------------------------------------------------
def _settings_digest() -> str:
    from arrange_up.physics.simulation import DEFAULT_SETTINGS

    return hashlib.sha256(repr(DEFAULT_SETTINGS).encode("utf-8")).hexdigest()[:16]


def _header(problem: ArrangementProblem, phash: str, lhash: str, n: int, seed: int) -> dict:
    return {
        "format": RECORD_FORMAT,
        "problem": {"name": problem.name, "hash": phash},
        "plan": {"hash": lhash, "actions": n},
        "seed": seed,
        "physics": _settings_digest(),
    }


_HEADER_KEYS: tuple[tuple[str, ...], ...] = (
    ("format",),
    ("problem", "hash"),
    ("plan", "hash"),
    ("seed",),
    ("physics",),
)


def _dig(data: Any, path: tuple[str, ...]) -> Any:
    for key in path:
        data = data.get(key) if isinstance(data, dict) else None
    return data


class _RecordFile:
    """An open, locked record file: its earlier records, and an append handle."""

    def __init__(self, path: Path, header: dict) -> None:
        self.path = path
        path.parent.mkdir(parents=True, exist_ok=True)
        self.handle: IO[bytes] = open(path, "a+b")  # noqa: SIM115 - closed by close()
        try:
            self._lock()
            self.records = self._read(header)
        except BaseException:
            self.handle.close()
            raise

    def _lock(self) -> None:
        try:
            import fcntl
        except ImportError:  # pragma: no cover - not on POSIX
            return
        try:
            fcntl.flock(self.handle.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise RecordFileError(
                f"{self.path}: the record file is in use by another evaluation"
            ) from None

    def _read(self, header: dict) -> dict[int, RolloutRecord]:
        handle = self.handle
        handle.seek(0)
        data = handle.read()
        if not data.strip():
            handle.truncate(0)
            self.write_line(header)
            return {}
        lines = data.split(b"\n")
        if not data.endswith(b"\n"):
            # the last line was cut off (a run killed while writing): drop it
            lines, cut = lines[:-1], lines[-1]
            handle.truncate(len(data) - len(cut))
        else:
            lines = lines[:-1]
        if not lines:  # killed while writing the header: start afresh
            self.write_line(header)
            return {}
        try:
            found = json.loads(lines[0])
        except ValueError:
            found = None
        if not isinstance(found, dict) or found.get("format") != RECORD_FORMAT:
            raise RecordFileError(
                f"{self.path}:1: not an arrange-up rollout record (its first line must be a "
                f"{RECORD_FORMAT!r} header); use another record file"
            )
        differ = [
            ".".join(path) for path in _HEADER_KEYS if _dig(found, path) != _dig(header, path)
        ]
        if differ:
            details = "; ".join(
                f"{'.'.join(p)}: file {_dig(found, p)!r}, this run {_dig(header, p)!r}"
                for p in _HEADER_KEYS
                if ".".join(p) in differ
            )
            raise RecordFileError(
                f"{self.path}: the record file belongs to another evaluation ({details}); its "
                "rollouts cannot be mixed with this one's: use another record file or delete it"
            )
        records: dict[int, RolloutRecord] = {}
        for number, line in enumerate(lines[1:], start=2):
            if not line.strip():
                continue
            try:
                record = RolloutRecord.from_json(json.loads(line))
            except (ValueError, KeyError, TypeError) as error:
                raise RecordFileError(
                    f"{self.path}:{number}: not a rollout record: {error}"
                ) from None
            earlier = records.get(record.index)
            if earlier is not None and earlier != record:
                raise RecordFileError(
                    f"{self.path}:{number}: rollout {record.index} is recorded twice with "
                    "different outcomes"
                )
            records[record.index] = record
        return records

    def write_line(self, data: dict) -> None:
        self.handle.write(json.dumps(data, separators=(",", ":")).encode("utf-8") + b"\n")
        self.handle.flush()

    def close(self) -> None:
        self.handle.close()  # also releases the lock


# ----------------------------------------------------------------------------------------------
# evaluation
# ----------------------------------------------------------------------------------------------
def evaluate_plan(
    problem: ArrangementProblem,
    actions: Sequence[Action],
    *,
    rollouts: int = 1000,
    seed: int = 0,
    workers: int | None = None,
    backend: str = "local",
    scheduler: str | None = None,
    record: str | Path | None = None,
    progress: ProgressCallback | None = None,
    chunksize: int | None = None,
    keep_records: bool = False,
) -> Reliability:
    """Estimate how often ``actions`` achieve ``problem``'s goal under its full noise.

    Parameters
    ----------
    rollouts
        Number of rollouts (indices ``0 .. rollouts - 1``).
    seed
        Non-negative integer; rollout ``i`` draws from ``default_rng([seed, i])``, so results
        do not depend on ``workers``, ``backend`` or ``chunksize``.
    workers, backend, scheduler
        Where rollouts run (:func:`arrange_up.parallel.get_runner`): ``"local"`` processes
        (``workers=None``: every core; 1 runs in this process) or ``"dask"`` (a LocalCluster
        of ``workers`` processes, or the cluster at the ``scheduler`` address).
    record
        A ``.jsonl`` file that every finished rollout is appended to; an existing file of the
        same evaluation is resumed (see the module docstring).
    progress
        Called with an :class:`EvaluationProgress` once at the start and after every
        rollout; an exception it raises (``KeyboardInterrupt``) stops the evaluation, with
        everything finished so far recorded.
    chunksize
        Rollouts per task (default :func:`arrange_up.parallel.auto_chunksize`: about four
        tasks per worker, at most 25 rollouts each).
    keep_records
        Keep every rollout's record in :attr:`Reliability.records`.

    Raises
    ------
    ValueError
        For bad arguments, or a problem whose initial belief cannot be sampled.
    RecordFileError
        For a record file of another evaluation.
    arrange_up.parallel.BackendUnavailableError
        When the backend is missing.
    """
    from arrange_up.parallel import BACKENDS, auto_chunksize, get_runner

    started = time.perf_counter()
    if not isinstance(rollouts, int) or isinstance(rollouts, bool) or rollouts < 1:
        raise ValueError(f"rollouts must be a positive integer, got {rollouts!r}")
    if not isinstance(seed, int) or isinstance(seed, bool) or seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    if backend not in BACKENDS:
        raise ValueError(f"unknown backend {backend!r}; expected one of {', '.join(BACKENDS)}")
    if chunksize is not None and (
        not isinstance(chunksize, int) or isinstance(chunksize, bool) or chunksize < 1
    ):
        raise ValueError(f"chunksize must be a positive integer, got {chunksize!r}")
    actions = tuple(actions)
    for action in actions:
        if not isinstance(action, Place | Push | Pick):
            raise ValueError(f"not an action: {action!r}")
    phash, lhash = problem_hash(problem), plan_hash(actions)
    _check_names(problem, actions)

    file = None
    records: dict[int, RolloutRecord] = {}
    if record is not None:
        file = _RecordFile(Path(record), _header(problem, phash, lhash, len(actions), seed))
        records = {i: r for i, r in file.records.items() if i < rollouts}
    resumed = len(records)
    successes = sum(r.success for r in records.values())
    runner_backend, runner_workers = backend, 1
    try:
        todo = [i for i in range(rollouts) if i not in records]
        if progress is not None:
            progress(EvaluationProgress(resumed, rollouts, successes, 0.0, resumed))
        if todo:
            runner = get_runner(backend, workers, scheduler)
            runner_workers = runner.workers
            size = chunksize or auto_chunksize(len(todo), runner.workers)
            context = _Context(f"{phash} {lhash}", problem, actions, seed)
            for index, result in runner.map(partial(_rollout_task, context), todo, size):
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
    finally:
        if file is not None:
            file.close()

    ordered = [records[i] for i in range(rollouts)]
    return Reliability(
        successes=successes,
        trials=rollouts,
        failures=FailureBreakdown.from_records(ordered),
        seed=seed,
        elapsed=time.perf_counter() - started,
        resumed=resumed,
        backend=runner_backend,
        workers=runner_workers,
        records=tuple(ordered) if keep_records else None,
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
