"""Plan repair with fixtures (thesis ch. 4): make a nominal plan robust by placing fixtures.

A *nominal plan* solves the deterministic relaxation of a problem (one particle, no noise).
:func:`repair_plan` turns every push of it into ``place(fixture), push, pick(fixture)``,
choosing where the fixture goes and how far the push drives so that the particle belief stays
as close as possible to the nominal trajectory ("control along the trajectory", §4.1.1)::

    from arrange_up.io.domains import load
    from arrange_up.repair.fixture_repair import nominal_plans, repair_plan

    problem = load("tz-mating")
    nominal = nominal_plans(problem, 1, seed=0)[0]
    result = repair_plan(problem, nominal, particles=150, seed=0, method="enhanced", workers=2)
    result.status, result.actions, result.steps[0].multiplier

The algorithm
=============
**Nominal plans** (:func:`nominal_plans`). The thesis re-ran its deterministic search and got
different plans from the non-unique ordering of Python's priority queue. Here that variety is
deliberate and reproducible: the first plan is the deterministic planner's with seeded
tie-breaking; the others come from the planner's ``variety`` flag (every push it proposes is,
by a seeded coin per belief, offered whole or cut to 40-80% of its distance), and only plans
that differ from those already found are kept. ``tie_break`` alone gave at most two distinct
plans in 20 seeds on the chapter-4 domains (the action generator proposes only goal-directed
pushes, so plans differ only in their order); with ``variety`` 20 seeds give 11-17 distinct
plans of 1 to 5 pushes.

**Multi-step repair** (Figure 4-7). The nominal states ``x_0 .. x_n`` come from the nominal plan
in the deterministic semantics; the belief ``b_0`` is the particle semantics' initial belief
(:class:`~arrange_up.transitions.particles.ParticleSemantics`, ``particles`` and ``seed``).
Step by step, a place or pick action is kept as it is; a push is replaced by the solution of
its one-step fixture problem; the belief is propagated through what replaced it. When
propagation fails (every candidate of a push makes some particle leave the table or never come
to rest) the repair stops with status ``"failed"`` and a reason naming the step: an honest
failure, never a silently unreliable plan.

**One-step fixture problem** (Figures 4-6, 4-8 to 4-10), for push ``u_i`` from belief ``b_i``:

1. *Placements.* A grid over the table (:data:`GRID_STEP` inches, fixture turned 0 and 90
   degrees, fewer angles for a symmetric fixture) for every fixture that is off the table.
   A placement must satisfy the place precondition on the current belief (its place shadow,
   pose +- place uncertainty, lies on the table and touches no wall, obstacle or shadow of an
   object of ``b_i``) and must not touch the paddle's approach shadow (approach pose +- push
   uncertainty); placements that fail are kept as ``blocked`` for the heatmap.
   ``method="naive"`` uses the whole grid (Figure 4-8). ``method="enhanced"`` keeps only
   placements whose footprint meets a *part motion swath* (Figure 4-9): for each part the push
   moves, the axis-aligned box over its footprints in ``b_i`` and after the push at twice its
   distance (the no-fixture candidate below, simulated for every particle).
2. *No fixture* is always a candidate too: the push alone. With it the repair never picks a
   fixture that scores worse on the belief than pushing without one, and a nominal push that
   is already reliable stays a bare push (no needless place and pick).
3. *Selecting a placement* (OPTIMIZEPLACEACTION): every candidate is simulated on every
   particle with the push at :data:`SELECTION_MULTIPLIER` (2x) its nominal distance and scored
   by SCOREACTIONS (Figure 4-10): the Manhattan distance (x plus y, inches) of every part from
   its pose in the nominal next state ``x_{i+1}``, summed over the parts and averaged over the
   particles. An outcome where any particle's push fails is *invalid*: distance infinite,
   score ``None``, left out of the min-max normalisation of the others' scores to [0, 1]
   (0 is best). When no candidate is valid at 2x, the selection falls back to the next smaller
   multiplier.
4. *Push distance* (OPTIMIZEPUSHDISTANCE): the best :data:`REFINE` placements and "no fixture"
   are simulated at every multiplier of :data:`MULTIPLIERS` (1, 1.25, 1.5, 1.75, 2; the push
   keeps its approach pose, only its distance grows) and the pair with the smallest distance
   wins (ties: the smaller multiplier). A fixture must beat the best bare push by more than
   :data:`MIN_FIXTURE_GAIN` (1%, at least 0.01 in): a fixture the parts never touch changes
   the simulation only by round-off, and placing it would add two actions and a place's risk
   for nothing. The thesis optimised the multiplier for the one best placement; keeping a few
   guards against a placement that is best at 2x only.
5. The push becomes ``place(fixture, pose), push(distance * multiplier), pick(fixture)``, or
   ``push(distance * multiplier)`` without a fixture.

Noise and work sharing
======================
* *Common random numbers.* Particle ``i`` draws its noise at step ``k`` from
  ``default_rng([seed, k, i])`` (one place draw and one push draw: pose offsets, friction,
  densities), the same for every candidate of the step. Candidates are then compared on the
  same worlds, which removes most of the noise from their ranking with few particles; the
  belief propagation is the same simulation as the scoring.
* *Reuse.* The propagated belief is the winning candidate's simulated outcome: nothing is
  simulated twice. The no-fixture simulation at 2x is also the swath's.
* *Unreachable fixtures.* As in the particle semantics, a push simulates only the objects its
  conservative sweep can reach. A placement outside that sweep cannot change the outcome, so
  it gets the no-fixture outcome of the same multiplier without any simulation (bit-identical:
  same noise, same simulated objects); it is never preferred to no fixture.
* *Early exit.* An invalid candidate is invalid as soon as one particle fails: each worker
  stops its share of the particles at the first failure.
* *Only a few multipliers.* Multipliers other than 2x are simulated for the :data:`REFINE`
  best placements and no fixture only (4 x 4 extra candidates a push).
* *Parallelism.* Particles of every candidate are split among ``workers`` processes (loky, as
  the particle semantics), all candidates of a stage in one batch.

Statuses: ``"solved"`` (every step repaired; ``actions`` is the repaired plan), ``"failed"``
(a step could not be propagated; ``reason`` says which and why), ``"timeout"``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from arrange_up.belief.states import IntervalBelief, ObjectInterval, ParticleBelief, symmetry_period
from arrange_up.geometry import shapes as geometry
from arrange_up.model.problem import ArrangementProblem, Pose
from arrange_up.model.world import (
    Action,
    ActionNoise,
    Pick,
    Place,
    Push,
    WorldState,
    draw_noise,
)

__all__ = [
    "FAILED",
    "GRID_STEP",
    "METHODS",
    "MULTIPLIERS",
    "REFINE",
    "REPAIR_SEMANTICS",
    "SELECTION_MULTIPLIER",
    "SOLVED",
    "TIMEOUT",
    "Candidate",
    "RepairResult",
    "StepRecord",
    "StepScores",
    "nominal_plans",
    "plan_groups",
    "repair_plan",
    "step_scores",
]

SOLVED = "solved"
FAILED = "failed"
TIMEOUT = "timeout"
#: The ``semantics`` a repaired plan file records.
REPAIR_SEMANTICS = "fixtures"
METHODS = ("naive", "enhanced")
#: Push distance multipliers (thesis §4.1.2, "Pushing multipliers").
MULTIPLIERS: tuple[float, ...] = (1.0, 1.25, 1.5, 1.75, 2.0)
#: The multiplier placements are selected and the swath is built with (thesis: 2x).
SELECTION_MULTIPLIER = 2.0
#: Spacing of the placement grid (inches).
GRID_STEP = 0.5
#: Placements whose multipliers are all tried (besides "no fixture").
REFINE = 3
#: Approach back-off: step, largest back-off, and clearance kept from the belief's shadows
#: (inches; see :meth:`_Repairer.clear_approach`).
BACKOFF_STEP = 0.05
MAX_BACKOFF = 2.0
BACKOFF_GAP = 0.02
#: A fixture is chosen only if it lowers the mean distance below the best bare push's by more
#: than ``max(absolute, relative * bare distance)`` (inches, fraction): physics round-off alone
#: makes an untouched fixture differ by ~1e-4.
MIN_FIXTURE_GAIN = (0.01, 0.01)
#: Default particles (the thesis's Figure 4-14 setting).
DEFAULT_PARTICLES = 150

#: Candidate statuses.
OK = "ok"
BLOCKED = "blocked"
INVALID = "invalid"

ProgressCallback = Callable[[dict[str, Any]], None]


# ---------------------------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Candidate:
    """One candidate of a one-step fixture problem.

    ``fixture``/``pose`` are ``None`` for "no fixture". ``status`` is ``"ok"`` (simulated on
    every particle, or unreachable by the push and given the no-fixture outcome:
    ``reachable=False``), ``"blocked"`` (the place precondition fails; not simulated) or
    ``"invalid"`` (some particle's push failed; ``reason`` says how). ``distance`` is the mean
    Manhattan distance to the nominal next state (``inf`` when invalid, ``nan`` when blocked);
    ``score`` its min-max normalised value among the valid candidates of the same stage (0 is
    best; ``None`` unless ``ok``). ``push`` is the push it simulates: the nominal push's
    (backed-off, see :class:`StepScores`) approach pose, its distance times ``multiplier``.
    """

    fixture: str | None
    pose: Pose | None
    multiplier: float
    status: str
    distance: float
    score: float | None = None
    reachable: bool = True
    reason: str = ""
    push: Push | None = None

    @property
    def valid(self) -> bool:
        return self.status == OK

    def actions(self) -> tuple[Action, ...]:
        """The actions this candidate replaces its nominal push with."""
        assert self.push is not None
        if self.fixture is None or self.pose is None:
            return (self.push,)
        return (Place(self.fixture, self.pose), self.push, Pick(self.fixture))

    def to_json(self, units: Any) -> dict[str, Any]:
        data: dict[str, Any] = {
            "fixture": self.fixture,
            "pose": None if self.pose is None else [_r(v) for v in units.pose_out(self.pose)],
            "multiplier": self.multiplier,
            "status": self.status,
            "distance": _json_float(self.distance),
            "score": None if self.score is None else _r(self.score),
        }
        if not self.reachable:
            data["reachable"] = False
        if self.reason:
            data["reason"] = self.reason
        return data


@dataclass(frozen=True)
class StepScores:
    """Everything the one-step fixture problem of one push computed (for records, heatmaps).

    ``step`` is the 0-based index of the push in the nominal plan. ``placements`` are the
    placement-stage candidates at ``selection_multiplier`` ("no fixture" first, then the grid
    placements in grid order, blocked ones included), ``refined`` the push-distance stage
    (every multiplier of the best placements and of no fixture), ``best`` the winner (``None``
    when every candidate is invalid). ``swaths`` holds ``(part, (xmin, ymin, xmax, ymax))``.
    ``backoff`` is how far the push's approach pose was moved back along the push (its
    distance grown by as much) so that its approach shadow clears the belief's shadows; 0 when
    it already did.
    """

    step: int
    push: Push
    backoff: float
    belief: ParticleBelief
    nominal_state: WorldState
    nominal_next: WorldState
    method: str
    selection_multiplier: float
    swaths: tuple[tuple[str, tuple[float, float, float, float]], ...]
    placements: tuple[Candidate, ...]
    refined: tuple[Candidate, ...]
    best: Candidate | None
    simulations: int
    elapsed: float
    after: ParticleBelief | None = field(default=None, repr=False, compare=False)

    @property
    def no_fixture(self) -> Candidate:
        """The "no fixture" candidate of the placement stage."""
        return self.placements[0]


@dataclass(frozen=True)
class StepRecord:
    """What the repair did with one action of the nominal plan.

    ``kind`` is the nominal action's type; ``actions`` what replaced it (the action itself for a
    place or pick). For a push: the chosen ``fixture``, ``pose`` and ``multiplier``, the chosen
    candidate's ``distance`` and the bare nominal push's (``nominal_distance``, multiplier 1,
    ``inf`` if invalid), the approach ``backoff`` (see :class:`StepScores`) and candidate
    counts. ``status`` is ``"ok"`` or ``"failed"``.
    """

    index: int
    kind: str
    nominal: Action
    actions: tuple[Action, ...]
    status: str = OK
    reason: str = ""
    fixture: str | None = None
    pose: Pose | None = None
    multiplier: float | None = None
    distance: float | None = None
    nominal_distance: float | None = None
    score: float | None = None
    placements: int = 0
    blocked: int = 0
    invalid: int = 0
    unreachable: int = 0
    selection_multiplier: float | None = None
    backoff: float = 0.0
    simulations: int = 0
    elapsed: float = 0.0

    def to_json(self, units: Any, first: int) -> dict[str, Any]:
        """JSON of the record; ``first`` is the index of its first action in the plan."""
        from arrange_up.io.planfile import action_to_json

        data: dict[str, Any] = {
            "step": self.index + 1,
            "kind": self.kind,
            "status": self.status,
            "nominal": action_to_json(self.nominal, units),
            "plan_actions": [first, first + len(self.actions)],
        }
        if self.reason:
            data["reason"] = self.reason
        if self.kind == "push":
            data.update(
                fixture=self.fixture,
                pose=None if self.pose is None else [_r(v) for v in units.pose_out(self.pose)],
                multiplier=self.multiplier,
                distance=_json_float(self.distance),
                nominal_distance=_json_float(self.nominal_distance),
                selection_multiplier=self.selection_multiplier,
                backoff=_r(self.backoff),
                placements=self.placements,
                blocked=self.blocked,
                invalid=self.invalid,
                unreachable=self.unreachable,
                simulations=self.simulations,
                elapsed=_r(self.elapsed),
            )
        return data


@dataclass(frozen=True)
class RepairResult:
    """The outcome of :func:`repair_plan`.

    ``actions`` is the repaired plan when ``status == "solved"``, else ``None`` (``partial``
    holds what was repaired before the failure). ``steps`` has one record per nominal action
    handled (the failing one last). ``beliefs`` holds the particle belief before the first
    action and after each step.
    """

    status: str
    actions: tuple[Action, ...] | None
    nominal: tuple[Action, ...]
    steps: tuple[StepRecord, ...]
    elapsed: float
    method: str
    particles: int
    seed: int
    reason: str = ""
    simulations: int = 0
    partial: tuple[Action, ...] = ()
    beliefs: tuple[ParticleBelief, ...] = field(default=(), repr=False, compare=False)

    @property
    def solved(self) -> bool:
        return self.status == SOLVED

    def stats(self) -> dict[str, Any]:
        """Summary statistics (the plan file's ``search`` object)."""
        pushes = [s for s in self.steps if s.kind == "push"]
        return {
            "elapsed": self.elapsed,
            "simulations": self.simulations,
            "steps": len(self.nominal),
            "pushes": len(pushes),
            "fixtures_placed": sum(1 for s in pushes if s.fixture is not None),
            "nominal_length": len(self.nominal),
            "plan_length": None if self.actions is None else len(self.actions),
        }

    def repair_json(self, problem: ArrangementProblem) -> dict[str, Any]:
        """The plan file's ``repair`` object: settings, the nominal plan, per-step choices."""
        from arrange_up.io.planfile import action_to_json

        steps, first = [], 0
        for record in self.steps:
            steps.append(record.to_json(problem.units, first))
            first += len(record.actions)
        data: dict[str, Any] = {
            "method": self.method,
            "particles": self.particles,
            "seed": self.seed,
            "multipliers": list(MULTIPLIERS),
            "grid_step": GRID_STEP,
            "nominal": [action_to_json(a, problem.units) for a in self.nominal],
            "steps": steps,
        }
        if self.reason:
            data["reason"] = self.reason
        return data

    def document(self, problem: ArrangementProblem) -> dict[str, Any]:
        """The plan file (:func:`arrange_up.io.planfile.plan_document`, semantics ``fixtures``)."""
        from arrange_up.io.planfile import plan_document

        return plan_document(
            problem,
            self.actions,
            status=self.status,
            semantics=REPAIR_SEMANTICS,
            seed=self.seed,
            search=self.stats(),
            extra={"particles": self.particles, "repair": self.repair_json(problem)},
        )


# ---------------------------------------------------------------------------------------------
# nominal plans
# ---------------------------------------------------------------------------------------------
def nominal_plans(
    problem: ArrangementProblem,
    k: int,
    seed: int = 0,
    *,
    max_tries: int | None = None,
    max_nodes: int | None = None,
) -> list[tuple[Action, ...]]:
    """Up to ``k`` distinct nominal (deterministic) plans, reproducibly from ``seed``.

    Try 0 is the deterministic planner with seeded tie-breaking; try ``j >= 1`` adds the
    planner's ``variety`` flag with the seed ``SeedSequence([seed, j])`` draws (see the module
    docstring). Plans equal to one already found are skipped. Returns fewer than ``k`` plans
    when ``max_tries`` (default ``10 * k + 10``) tries found no more distinct ones, and an empty
    list when the deterministic planner solves none.
    """
    from arrange_up.planning.planner import plan

    if k < 1:
        raise ValueError(f"k must be at least 1, got {k!r}")
    tries = max_tries if max_tries is not None else 10 * k + 10
    found: list[tuple[Action, ...]] = []
    seen: set[tuple[Action, ...]] = set()
    for j in range(tries):
        planner_seed = seed if j == 0 else _derived_seed(seed, j)
        result = plan(
            problem,
            semantics="deterministic",
            seed=planner_seed,
            tie_break=True,
            variety=j > 0,
            max_nodes=max_nodes,
        )
        if result.actions is None or result.actions in seen:
            continue
        seen.add(result.actions)
        found.append(result.actions)
        if len(found) == k:
            break
    return found


def _derived_seed(seed: int, j: int) -> int:
    return int(np.random.SeedSequence([seed, j]).generate_state(1)[0])


# ---------------------------------------------------------------------------------------------
# the repair
# ---------------------------------------------------------------------------------------------
def repair_plan(
    problem: ArrangementProblem,
    actions: Sequence[Action],
    *,
    particles: int = DEFAULT_PARTICLES,
    seed: int = 0,
    method: str = "enhanced",
    workers: int = 1,
    progress: ProgressCallback | None = None,
    timeout: float | None = None,
) -> RepairResult:
    """Repair the nominal plan ``actions`` with fixtures (thesis Figure 4-7; module docstring).

    Parameters
    ----------
    particles, seed
        The particle belief: ``particles`` initial states drawn as the particle semantics draws
        them from ``seed``; every noise draw derives from ``seed`` too, so equal arguments give
        equal results whatever ``workers``.
    method
        ``"enhanced"`` (placements meeting the part motion swath) or ``"naive"`` (the whole
        grid).
    workers
        Processes simulating particles (1: in this process).
    progress
        Called with a dict after each phase of each step: ``step`` (1-based), ``steps``,
        ``kind``, ``phase`` (``"placements"``, ``"refine"``, ``"done"``), ``candidates``,
        ``elapsed`` and, when done, ``choice`` (a short text).
    timeout
        Wall-clock seconds; checked between batches of candidates (status ``"timeout"``).

    Raises ``ValueError`` for bad arguments, or a nominal plan that fails in the deterministic
    semantics (it is not a nominal plan of ``problem``).
    """
    started = time.monotonic()
    deadline = None if timeout is None else started + timeout
    actions = tuple(actions)
    repairer = _Repairer(problem, particles, seed, method, workers, deadline)
    records: list[StepRecord] = []
    out: list[Action] = []

    def result(status: str, plan, reason: str = "", beliefs=()) -> RepairResult:
        return RepairResult(
            status,
            plan,
            actions,
            tuple(records),
            time.monotonic() - started,
            method,
            particles,
            seed,
            reason=reason,
            simulations=repairer.simulations,
            partial=tuple(out),
            beliefs=tuple(beliefs),
        )

    try:
        states = repairer.nominal_states(actions)
        belief = repairer.initial_belief()
        beliefs = [belief]
        for index, action in enumerate(actions):
            step_started = time.monotonic()
            sims_before = repairer.simulations
            if isinstance(action, Push):
                scores = repairer.one_step(
                    belief, index, action, states[index], states[index + 1], progress, len(actions)
                )
                record = _push_record(index, action, scores)
                after = scores.after
            else:
                after, reason = repairer.propagate(belief, index, (action,))
                record = StepRecord(
                    index,
                    type(action).__name__.lower(),
                    action,
                    (action,),
                    status=OK if after is not None else FAILED,
                    reason=reason,
                    simulations=repairer.simulations - sims_before,
                    elapsed=time.monotonic() - step_started,
                )
            records.append(record)
            if after is None:
                reason = f"step {index + 1} ({record.kind}): {record.reason}"
                return result(FAILED, None, reason, beliefs)
            out.extend(record.actions)
            belief = after
            beliefs.append(belief)
            if progress is not None:
                progress(
                    {
                        "step": index + 1,
                        "steps": len(actions),
                        "kind": record.kind,
                        "phase": "done",
                        "candidates": record.placements,
                        "elapsed": time.monotonic() - started,
                        "choice": _describe_choice(record, problem),
                    }
                )
        return result(SOLVED, tuple(out), beliefs=beliefs)
    except _OutOfTime:
        return result(TIMEOUT, None, f"timeout of {timeout} s reached")
    finally:
        repairer.close()


def plan_groups(
    problem: ArrangementProblem, actions: Sequence[Action], document: dict[str, Any] | None
) -> tuple[tuple[Action, ...], tuple[tuple[Action, ...], ...], dict[str, Any]]:
    """Split a plan read from a file into ``(nominal, groups, settings)``.

    For a repaired plan (its document has a ``repair`` object) ``nominal`` is the nominal plan
    recorded there, ``groups[k]`` the actions that replaced nominal action ``k`` and
    ``settings`` the repair's ``particles``, ``seed`` and ``method``. For any other plan the
    plan is its own nominal plan, one action per group, and ``settings`` is empty.
    """
    from arrange_up.io.planfile import PlanFileError, action_from_json
    from arrange_up.model.units import Units

    actions = tuple(actions)
    repair = (document or {}).get("repair")
    if not isinstance(repair, dict):
        return actions, tuple((a,) for a in actions), {}
    raw_units = (document or {}).get("units", {})
    units = Units(raw_units.get("length", "in"), raw_units.get("angle", "deg"))
    try:
        nominal = tuple(
            action_from_json(item, units, problem, f"repair.nominal[{i}]")
            for i, item in enumerate(repair["nominal"])
        )
        groups = []
        for record in repair["steps"]:
            start, stop = record["plan_actions"]
            groups.append(actions[start:stop])
    except (KeyError, TypeError, ValueError) as error:
        raise PlanFileError(f"repair: malformed repair record: {error}") from None
    settings = {key: repair[key] for key in ("particles", "seed", "method") if key in repair}
    return nominal, tuple(groups), settings


def step_scores(
    problem: ArrangementProblem,
    actions: Sequence[Action],
    step: int,
    *,
    document: dict[str, Any] | None = None,
    particles: int | None = None,
    seed: int | None = None,
    method: str | None = None,
    workers: int = 1,
) -> StepScores:
    """Score every candidate placement of one push (thesis Figure 4-11's heatmap data).

    ``actions`` and ``document`` are what :func:`arrange_up.io.planfile.read_plan` returns.
    ``step`` is the 1-based number of a push in the *nominal* plan: for a nominal plan its
    action number; for a repaired plan (see :func:`plan_groups`) the step number its
    ``repair.steps`` records, whose nominal plan, particles, seed and method are then the
    defaults, and whose earlier steps' repaired actions take the belief to the step, so the
    scores are the ones the repair saw (up to the rounding of numbers in the plan file).
    Without a repair record the defaults are 150 particles, seed 0, enhanced.

    Raises ``ValueError`` when ``step`` is out of range or not a push, or when the belief
    cannot be propagated to it.
    """
    nominal, groups, settings = plan_groups(problem, actions, document)
    if not 1 <= step <= len(nominal):
        raise ValueError(f"step {step} is out of range: the nominal plan has {len(nominal)} steps")
    push = nominal[step - 1]
    if not isinstance(push, Push):
        raise ValueError(
            f"step {step} is a {type(push).__name__.lower()}, not a push: only pushes have "
            "fixture candidates"
        )
    if step - 1 > len(groups):
        raise ValueError(f"the repair record stops before step {step}")
    particles = particles if particles is not None else int(settings.get("particles", 150))
    seed = seed if seed is not None else int(settings.get("seed", 0))
    method = method if method is not None else str(settings.get("method", "enhanced"))
    repairer = _Repairer(problem, particles, seed, method, workers, None)
    try:
        states = repairer.nominal_states(nominal)
        belief = repairer.initial_belief()
        for k in range(step - 1):
            after, reason = repairer.propagate(belief, k, groups[k])
            if after is None:
                raise ValueError(f"the belief cannot be propagated through step {k + 1}: {reason}")
            belief = after
        return repairer.one_step(belief, step - 1, push, states[step - 1], states[step])
    finally:
        repairer.close()


# ---------------------------------------------------------------------------------------------
# internals
# ---------------------------------------------------------------------------------------------
class _OutOfTime(Exception):
    pass


_PLACE = Place("-", (0.0, 0.0, 0.0))
_PUSH = Push("-", (0.0, 0.0, 0.0), 0.0)
_ZERO = (0.0, 0.0, 0.0)


@dataclass
class _Outcome:
    """A candidate simulated on every particle: the belief after it, or why it failed."""

    belief: ParticleBelief | None
    distance: float
    reason: str = ""
    reachable: bool = True


class _Repairer:
    """State shared by the steps of one repair: the problem, semantics, noise and pool."""

    def __init__(
        self,
        problem: ArrangementProblem,
        particles: int,
        seed: int,
        method: str,
        workers: int,
        deadline: float | None,
    ) -> None:
        from arrange_up.transitions.particles import ParticleSemantics

        if method not in METHODS:
            raise ValueError(f"unknown method {method!r}; expected one of {', '.join(METHODS)}")
        if not isinstance(particles, int) or isinstance(particles, bool) or particles < 1:
            raise ValueError(f"particles must be a positive integer, got {particles!r}")
        if not isinstance(seed, int) or isinstance(seed, bool):
            raise ValueError(f"seed must be an integer, got {seed!r}")
        if not isinstance(workers, int) or isinstance(workers, bool) or workers < 1:
            raise ValueError(f"workers must be a positive integer, got {workers!r}")
        self.problem = problem
        self.particles = particles
        self.seed = seed
        self.method = method
        self.workers = workers
        self.deadline = deadline
        self.semantics = ParticleSemantics(problem, particles=particles, seed=seed, workers=1)
        self.checker = self.semantics.checker
        self.frame = self.semantics.frame
        self.simulations = 0
        self.parts = tuple(spec.name for spec in problem.parts)
        self._noise: dict[int, list[tuple[ActionNoise, ActionNoise]]] = {}
        self._executor: Any = None
        self._intervals: dict[int, tuple[ParticleBelief, IntervalBelief]] = {}

    # -- setup ---------------------------------------------------------------------------------
    def initial_belief(self) -> ParticleBelief:
        return self.semantics.initial_belief()

    def nominal_states(self, actions: Sequence[Action]) -> list[WorldState]:
        """``x_0 .. x_n`` of the nominal plan in the deterministic semantics."""
        from arrange_up.transitions.particles import DeterministicSemantics

        model = DeterministicSemantics(self.problem)
        belief = model.initial_belief()
        states = [belief.particles[0]]
        for k, action in enumerate(actions):
            try:
                after = model.apply(belief, action)
            except (ValueError, KeyError) as error:
                raise ValueError(f"nominal action {k + 1} cannot be applied: {error}") from None
            if after is None:
                raise ValueError(
                    f"nominal action {k + 1} fails in the deterministic semantics (an object "
                    "leaves the table or never comes to rest): not a nominal plan of "
                    f"{self.problem.name!r}"
                )
            belief = after
            states.append(belief.particles[0])
        return states

    def noise(self, step: int) -> list[tuple[ActionNoise, ActionNoise]]:
        """Per particle: (place noise, push noise) of step ``step`` (common random numbers)."""
        if step not in self._noise:
            draws = []
            for i in range(self.particles):
                rng = np.random.default_rng([self.seed, 0xF1C, step, i])
                draws.append(
                    (draw_noise(self.problem, _PLACE, rng), draw_noise(self.problem, _PUSH, rng))
                )
            self._noise[step] = draws
        return self._noise[step]

    def close(self) -> None:
        self._executor = None

    def _check_time(self) -> None:
        if self.deadline is not None and time.monotonic() >= self.deadline:
            raise _OutOfTime

    def intervals(self, belief: ParticleBelief) -> IntervalBelief:
        """The belief's interval belief with angles spanned the short way round.

        :attr:`ParticleBelief.intervals` takes the min and max of the canonically wrapped
        angles; a part whose angle sits on the wrap boundary of its symmetry period (tz-mating's
        Z: period pi, at 90 degrees) then spans nearly a whole period, and its shadows cover
        every orientation. Here each object's angles are unwrapped around its first particle's
        before taking min and max, so the interval is as tight as the particles.
        """
        cached = self._intervals.get(id(belief))
        if cached is not None and cached[0] is belief:
            return cached[1]
        names = belief.names()
        poses = belief.poses.copy()
        if names:
            period = np.array([self.frame.period[name] for name in names])
            first = poses[0, :, 2]
            poses[:, :, 2] = first + (poses[:, :, 2] - first + 0.5 * period) % period - 0.5 * period
            low, high = poses.min(axis=0), poses.max(axis=0)
            result = IntervalBelief(
                tuple(
                    (name, ObjectInterval.from_bounds(low[k], high[k]))
                    for k, name in enumerate(names)
                )
            )
        else:
            result = IntervalBelief(())
        if len(self._intervals) > 64:
            self._intervals.clear()
        self._intervals[id(belief)] = (belief, result)
        return result

    # -- propagation -----------------------------------------------------------------------------
    def _place(self, belief: ParticleBelief, step: int, obj: str, pose: Pose) -> ParticleBelief:
        noise = self.noise(step)
        states = []
        for i, state in enumerate(belief.particles):
            poses = state.as_dict()
            if obj in poses:
                raise ValueError(f"place: {obj!r} is already on the table")
            offset = noise[i][0].pose_offset
            poses[obj] = (pose[0] + offset[0], pose[1] + offset[1], pose[2] + offset[2])
            states.append(self.frame.canonical(WorldState.from_mapping(self.problem, poses)))
        return ParticleBelief(tuple(states))

    def _pick(self, belief: ParticleBelief, obj: str) -> ParticleBelief:
        states = []
        for state in belief.particles:
            poses = state.as_dict()
            poses.pop(obj, None)
            states.append(WorldState.from_mapping(self.problem, poses))
        return ParticleBelief(tuple(states))

    def propagate(
        self, belief: ParticleBelief, step: int, group: Sequence[Action]
    ) -> tuple[ParticleBelief | None, str]:
        """Apply a group of actions (one nominal step's replacement) with step ``step``'s noise."""
        for action in group:
            if isinstance(action, Place):
                belief = self._place(belief, step, action.obj, action.pose)
            elif isinstance(action, Pick):
                belief = self._pick(belief, action.obj)
            elif isinstance(action, Push):
                [result] = self._pushes([(belief, action)], step, stop_on_failure=True)
                if result.belief is None:
                    return None, result.reason
                belief = result.belief
            else:
                raise TypeError(f"not an action: {action!r}")
        return belief, ""

    # -- simulation ------------------------------------------------------------------------------
    def _pool(self) -> Any:
        if self._executor is None:
            from joblib.externals.loky import get_reusable_executor

            self._executor = get_reusable_executor(max_workers=self.workers)
        return self._executor

    def _pushes(
        self,
        batch: Sequence[tuple[ParticleBelief, Push]],
        step: int,
        *,
        stop_on_failure: bool,
        distance_to: WorldState | None = None,
    ) -> list[_Outcome]:
        """Simulate each ``(belief, push)`` of ``batch`` on every particle, in one batch.

        Only the objects the push's conservative sweep can reach are simulated. With
        ``stop_on_failure`` a worker stops its particles at the first failure (the outcome is
        invalid anyway). The outcome's belief is ``None`` when a particle failed.
        """
        self._check_time()
        noise = self.noise(step)
        tasks: list[tuple[int, list[int], list[Any]]] = []
        affected_sets = []
        for b, (belief, push) in enumerate(batch):
            affected = self.semantics.affected_objects(self.intervals(belief), push)
            affected_sets.append(affected)
            if not affected:
                continue
            jobs = []
            for i, state in enumerate(belief.particles):
                sub = WorldState(tuple((n, p) for n, p in state.poses if n in affected))
                jobs.append((sub, push, noise[i][1]))
            shares = self.workers if self.workers > 1 and len(jobs) >= 2 * self.workers else 1
            for k in range(shares):
                indices = list(range(k, len(jobs), shares))
                tasks.append((b, indices, [jobs[i] for i in indices]))
        if self.workers > 1 and len(tasks) > 1:
            results = list(
                self._pool().map(
                    _simulate_jobs,
                    [self.problem] * len(tasks),
                    [t[2] for t in tasks],
                    [stop_on_failure] * len(tasks),
                )
            )
        else:
            results = [_simulate_jobs(self.problem, t[2], stop_on_failure) for t in tasks]
        per_candidate: list[dict[int, Any]] = [{} for _ in batch]
        failures: list[str] = ["" for _ in batch]
        for (b, indices, _jobs), result in zip(tasks, results, strict=True):
            self.simulations += len(result)
            for i, outcome in zip(indices, result, strict=False):
                status, off, poses = outcome
                per_candidate[b][i] = poses
                if status != "ok" and not failures[b]:
                    failures[b] = _failure_text(status, off)
        outcomes = []
        for b, (belief, _push) in enumerate(batch):
            if failures[b]:
                outcomes.append(_Outcome(None, math.inf, failures[b]))
                continue
            if not affected_sets[b]:
                after = belief
            else:
                states = []
                for i, state in enumerate(belief.particles):
                    poses = state.as_dict()
                    poses.update(per_candidate[b][i])
                    states.append(
                        self.frame.canonical(WorldState.from_mapping(self.problem, poses))
                    )
                after = ParticleBelief(tuple(states))
            distance = math.nan if distance_to is None else self.distance(after, distance_to)
            outcomes.append(_Outcome(after, distance))
        return outcomes

    def _raw_poses(
        self, belief: ParticleBelief, push: Push, step: int
    ) -> tuple[list[dict[str, Pose]], str]:
        """Every particle's poses after ``push`` even when some fail (for the swath)."""
        self._check_time()
        noise = self.noise(step)
        affected = self.semantics.affected_objects(self.intervals(belief), push)
        if not affected:
            return [dict(s.poses) for s in belief.particles], ""
        jobs = []
        for i, state in enumerate(belief.particles):
            jobs.append(
                (
                    WorldState(tuple((n, p) for n, p in state.poses if n in affected)),
                    push,
                    noise[i][1],
                )
            )
        shares = self.workers if self.workers > 1 and len(jobs) >= 2 * self.workers else 1
        chunks = [list(range(k, len(jobs), shares)) for k in range(shares)]
        if shares > 1:
            results = list(
                self._pool().map(
                    _simulate_jobs,
                    [self.problem] * shares,
                    [[jobs[i] for i in c] for c in chunks],
                    [False] * shares,
                )
            )
        else:
            results = [_simulate_jobs(self.problem, jobs, False)]
        poses: list[dict[str, Pose]] = [dict(s.poses) for s in belief.particles]
        failure = ""
        for chunk, result in zip(chunks, results, strict=True):
            self.simulations += len(result)
            for i, (status, off, moved) in zip(chunk, result, strict=True):
                poses[i].update(moved)
                if status != "ok" and not failure:
                    failure = _failure_text(status, off)
        return poses, failure

    def distance(self, belief: ParticleBelief, nominal: WorldState) -> float:
        """SCOREACTIONS's DISTANCE averaged over particles: per particle the Manhattan distance
        (x + y) of every part from its nominal pose, summed over the parts."""
        names = belief.names()
        nominal_poses = nominal.as_dict()
        columns = [k for k, n in enumerate(names) if n in nominal_poses and n in self.parts]
        if not columns:
            return 0.0
        target = np.array([nominal_poses[names[k]][:2] for k in columns])
        diff = np.abs(belief.poses[:, columns, :2] - target[None, :, :])
        return float(diff.sum(axis=(1, 2)).mean())

    # -- the one-step fixture problem ---------------------------------------------------------
    def clear_approach(self, belief: ParticleBelief, push: Push) -> tuple[Pose, float]:
        """The push's approach pose moved back along the push, in steps of
        :data:`BACKOFF_STEP`, until its approach shadow (pose +- push uncertainty) clears every
        shadow of ``belief`` with :data:`BACKOFF_GAP` to spare (the push precondition of
        :mod:`arrange_up.planning.actions`, on the belief instead of the nominal state); and how
        far.
        Gives up at :data:`MAX_BACKOFF` (the push then keeps its pose and fails in the particles
        it lands on)."""
        spec = self.problem.object(push.manipulator)
        px, py = spec.push_direction
        c, s = math.cos(push.pose[2]), math.sin(push.pose[2])
        ux, uy = c * px - s * py, s * px + c * py
        half = tuple(
            v + BACKOFF_GAP if k < 2 else v for k, v in enumerate(self.problem.uncertainty.push)
        )
        others = [(name, iv.center, iv.half) for name, iv in self.intervals(belief).objects]
        n = int(round(MAX_BACKOFF / BACKOFF_STEP))
        for k in range(n + 1):
            b = round(k * BACKOFF_STEP, 9)
            pose = (
                _round(push.pose[0] - b * ux),
                _round(push.pose[1] - b * uy),
                push.pose[2],
            )
            if not any(
                self.checker.shadows_overlap((push.manipulator, pose, half), other)  # type: ignore[arg-type]
                for other in others
            ):
                return pose, b
        return push.pose, 0.0

    def placements(self, belief: ParticleBelief, push: Push) -> list[tuple[str, Pose, bool]]:
        """Grid placements of every fixture off the table: ``(fixture, pose, allowed)``."""
        width, depth = self.problem.table.size
        place_unc = self.problem.uncertainty.place
        others = [(name, iv.center, iv.half) for name, iv in self.intervals(belief).objects]
        others.append((push.manipulator, push.pose, self.problem.uncertainty.push))
        xs = _grid(width, GRID_STEP)
        ys = _grid(depth, GRID_STEP)
        out = []
        for spec in self.problem.fixtures:
            if spec.name in belief.names():
                continue
            period = symmetry_period(spec.shape)
            angles = sorted({round(a % period, 9) for a in (0.0, 0.5 * math.pi)})
            for theta in angles:
                for y in ys:
                    for x in xs:
                        pose = (x, y, theta)
                        allowed = self.checker.shadow_inside_table(
                            spec.name, pose, place_unc
                        ) and self.checker.shadow_clear(spec.name, pose, place_unc, others)
                        out.append((spec.name, pose, allowed))
        return out

    def swaths(
        self, belief: ParticleBelief, after: list[dict[str, Pose]]
    ) -> tuple[tuple[str, tuple[float, float, float, float]], ...]:
        """Part motion swaths: per part that moved, the box over its footprints before/after."""
        out = []
        for name in belief.names():
            if name not in self.parts:
                continue
            before = [dict(s.poses)[name] for s in belief.particles]
            final = [p[name] for p in after if name in p]
            if all(
                math.dist(a[:2], b[:2]) < 1e-6 and abs(a[2] - b[2]) < 1e-6
                for a, b in zip(before, final, strict=True)
            ):
                continue
            boxes = [self.checker.shadow_box(name, pose, _ZERO) for pose in before + final]
            box = (
                min(b[0] for b in boxes),
                min(b[1] for b in boxes),
                max(b[2] for b in boxes),
                max(b[3] for b in boxes),
            )
            out.append((name, box))
        return tuple(out)

    def one_step(
        self,
        belief: ParticleBelief,
        step: int,
        push: Push,
        state: WorldState,
        nominal_next: WorldState,
        progress: ProgressCallback | None = None,
        steps: int = 0,
    ) -> StepScores:
        """ONESTEPFIXTUREPROBLEM (Figure 4-6) for ``push`` from ``belief``."""
        started = time.monotonic()
        sims_before = self.simulations

        approach, backoff = self.clear_approach(belief, push)

        def pushed(m: float) -> Push:
            return Push(push.manipulator, approach, _round(push.distance * m + backoff))

        # 1. swath from the no-fixture push at the selection multiplier (every particle)
        raw, failure = self._raw_poses(belief, pushed(SELECTION_MULTIPLIER), step)
        swaths = self.swaths(belief, raw)
        cache: dict[tuple[str | None, Pose | None, float], _Outcome] = {}
        if failure:
            cache[(None, None, SELECTION_MULTIPLIER)] = _Outcome(None, math.inf, failure)
        else:
            states = tuple(
                self.frame.canonical(WorldState.from_mapping(self.problem, poses)) for poses in raw
            )
            bare = ParticleBelief(states)
            distance = self.distance(bare, nominal_next)
            cache[(None, None, SELECTION_MULTIPLIER)] = _Outcome(bare, distance)
        grid = self.placements(belief, pushed(1.0))
        if self.method == "enhanced":
            grid = [
                g
                for g in grid
                if any(
                    geometry.boxes_overlap(self.checker.shadow_box(g[0], g[1], _ZERO), box)
                    for _, box in swaths
                )
            ]
        allowed = [g for g in grid if g[2]]
        if progress is not None:
            progress(
                {
                    "step": step + 1,
                    "steps": steps,
                    "kind": "push",
                    "phase": "placements",
                    "candidates": len(allowed) + 1,
                    "elapsed": time.monotonic() - started,
                }
            )

        def evaluate(keys: list[tuple[str | None, Pose | None, float]]) -> None:
            """Simulate the candidates of ``keys`` not yet in ``cache`` (no fixture first)."""
            todo = [key for key in keys if key not in cache]
            bare = [key for key in todo if key[0] is None]
            if bare:
                results = self._pushes(
                    [(belief, pushed(m)) for _, _, m in bare],
                    step,
                    stop_on_failure=True,
                    distance_to=nominal_next,
                )
                cache.update(zip(bare, results, strict=True))
            batch, batch_keys = [], []
            for key in todo:
                fixture, pose, m = key
                if fixture is None or pose is None:
                    continue
                placed = self._place(belief, step, fixture, pose)
                affected = self.semantics.affected_objects(self.intervals(placed), pushed(m))
                if fixture not in affected:
                    base = cache[(None, None, m)]
                    cache[key] = _Outcome(base.belief, base.distance, base.reason, reachable=False)
                    continue
                batch.append((placed, pushed(m)))
                batch_keys.append(key)
            if batch:
                results = self._pushes(batch, step, stop_on_failure=True)
                for key, result in zip(batch_keys, results, strict=True):
                    if result.belief is not None:
                        after = self._pick(result.belief, key[0])  # type: ignore[arg-type]
                        result = _Outcome(after, self.distance(after, nominal_next))
                    cache[key] = result

        # 2-3. placements at the selection multiplier (falling back to smaller ones)
        selection = SELECTION_MULTIPLIER
        for m in sorted(MULTIPLIERS, reverse=True):
            selection = m
            keys = [(None, None, m)] + [(f, p, m) for f, p, _ in allowed]
            evaluate(keys)
            if any(cache[key].belief is not None for key in keys):
                break
        placement_candidates = self._candidates(
            [(None, None, True)] + grid, selection, cache, pushed
        )
        # 4. multipliers for the best few placements and no fixture
        ranked = sorted(
            (c for c in placement_candidates if c.valid and c.fixture is not None and c.reachable),
            key=lambda c: c.distance,
        )[:REFINE]
        if progress is not None:
            progress(
                {
                    "step": step + 1,
                    "steps": steps,
                    "kind": "push",
                    "phase": "refine",
                    "candidates": (len(ranked) + 1) * len(MULTIPLIERS),
                    "elapsed": time.monotonic() - started,
                }
            )
        refine_keys = [(None, None, m) for m in MULTIPLIERS] + [
            (c.fixture, c.pose, m) for c in ranked for m in MULTIPLIERS
        ]
        evaluate(refine_keys)
        refined = _normalise([_candidate(key, cache[key], pushed(key[2])) for key in refine_keys])
        valid = [c for c in refined if c.valid]
        best = _choose(valid)
        after = None
        if best is not None:
            after = cache[(best.fixture, best.pose, best.multiplier)].belief
        return StepScores(
            step=step,
            push=push,
            backoff=backoff,
            belief=belief,
            nominal_state=state,
            nominal_next=nominal_next,
            method=self.method,
            selection_multiplier=selection,
            swaths=swaths,
            placements=tuple(placement_candidates),
            refined=tuple(refined),
            best=best,
            simulations=self.simulations - sims_before,
            elapsed=time.monotonic() - started,
            after=after,
        )

    def _candidates(
        self,
        grid: list[tuple[str | None, Pose | None, bool]],
        multiplier: float,
        cache: dict[tuple[str | None, Pose | None, float], _Outcome],
        pushed: Callable[[float], Push],
    ) -> list[Candidate]:
        out = []
        for fixture, pose, allowed in grid:
            if not allowed:
                out.append(
                    Candidate(
                        fixture,
                        pose,
                        multiplier,
                        BLOCKED,
                        math.nan,
                        reason="the place precondition fails on the belief's shadows",
                        push=pushed(multiplier),
                    )
                )
                continue
            key = (fixture, pose, multiplier)
            out.append(_candidate(key, cache[key], pushed(multiplier)))
        return _normalise(out)


def _candidate(
    key: tuple[str | None, Pose | None, float], outcome: _Outcome, push: Push
) -> Candidate:
    fixture, pose, multiplier = key
    if outcome.belief is None:
        return Candidate(
            fixture,
            pose,
            multiplier,
            INVALID,
            math.inf,
            reachable=outcome.reachable,
            reason=outcome.reason,
            push=push,
        )
    return Candidate(
        fixture, pose, multiplier, OK, outcome.distance, reachable=outcome.reachable, push=push
    )


def _choose(valid: list[Candidate]) -> Candidate | None:
    """The winner among valid candidates: the smallest distance (ties: the smaller
    multiplier), except that a fixture must beat the best bare push by
    :data:`MIN_FIXTURE_GAIN` (see the module docstring)."""
    if not valid:
        return None
    bare = [c for c in valid if c.fixture is None or not c.reachable]
    fixed = [c for c in valid if c.fixture is not None and c.reachable]
    best_bare = min(bare, key=lambda c: (c.distance, c.multiplier), default=None)
    best_fixed = min(fixed, key=lambda c: (c.distance, c.multiplier), default=None)
    if best_fixed is None:
        return best_bare
    if best_bare is None:
        return best_fixed
    gain = best_bare.distance - best_fixed.distance
    if gain > max(MIN_FIXTURE_GAIN[0], MIN_FIXTURE_GAIN[1] * best_bare.distance):
        return best_fixed
    return best_bare


def _normalise(candidates: list[Candidate]) -> list[Candidate]:
    """Figure 4-10's min-max scaling over the valid candidates (invalid ones keep None)."""
    finite = [c.distance for c in candidates if c.valid]
    if not finite:
        return candidates
    low, high = min(finite), max(finite)
    span = high - low
    return [
        replace(c, score=(c.distance - low) / span if span > 0 else 0.0) if c.valid else c
        for c in candidates
    ]


def _push_record(index: int, push: Push, scores: StepScores) -> StepRecord:
    best = scores.best
    bare = next(c for c in scores.refined if c.fixture is None and c.multiplier == 1.0)
    placements = [c for c in scores.placements if c.fixture is not None]
    common = {
        "placements": len(placements),
        "blocked": sum(1 for c in placements if c.status == BLOCKED),
        "invalid": sum(1 for c in scores.placements if c.status == INVALID),
        "unreachable": sum(1 for c in placements if not c.reachable),
        "selection_multiplier": scores.selection_multiplier,
        "backoff": scores.backoff,
        "nominal_distance": bare.distance,
        "simulations": scores.simulations,
        "elapsed": scores.elapsed,
    }
    if best is None:
        reasons = sorted({c.reason for c in scores.refined if c.reason})
        return StepRecord(
            index,
            "push",
            push,
            (),
            status=FAILED,
            reason="every candidate is invalid (no fixture and "
            f"{len(placements) - common['blocked']} placements, multipliers "
            f"{', '.join(f'{m:g}' for m in MULTIPLIERS)}): " + "; ".join(reasons),
            **common,
        )
    return StepRecord(
        index,
        "push",
        push,
        best.actions(),
        fixture=best.fixture,
        pose=best.pose,
        multiplier=best.multiplier,
        distance=best.distance,
        score=best.score,
        **common,
    )


def _describe_choice(record: StepRecord, problem: ArrangementProblem) -> str:
    if record.kind != "push":
        return f"{record.kind} kept"
    units = problem.units
    distance = f"distance {record.distance:.3f} (bare push {record.nominal_distance:.3f})"
    if record.fixture is None or record.pose is None:
        return f"no fixture, x{record.multiplier:g}, {distance}"
    x, y, theta = units.pose_out(record.pose)
    return (
        f"{record.fixture} at ({x:.3g}, {y:.3g}, {theta:.3g}), x{record.multiplier:g}, {distance}"
    )


def _simulate_jobs(problem: ArrangementProblem, jobs: list[Any], stop_on_failure: bool) -> list:
    """Simulate pushes: ``(status, off_table, moved poses)`` each; with ``stop_on_failure``
    the list ends at the first failure."""
    from arrange_up.physics.simulation import simulate

    out = []
    for state, push, noise in jobs:
        outcome = simulate(problem, state, push, noise)
        out.append((outcome.status.value, outcome.off_table, outcome.state.poses))
        if stop_on_failure and not outcome.ok:
            break
    return out


def _failure_text(status: str, off: Sequence[str]) -> str:
    if status == "off_table":
        return f"a particle's push put {', '.join(off)} off the table"
    if status == "not_at_rest":
        return "a particle's push did not come to rest"
    if status == "overlap":
        return "a particle's push started with shapes overlapping"
    return f"a particle's push failed ({status})"


def _grid(size: float, step: float) -> list[float]:
    n = int(math.floor(size / step + 1e-9))
    return [round(k * step, 9) for k in range(1, n) if k * step < size - 1e-9]


def _round(value: float) -> float:
    return round(float(value), 6) + 0.0


def _r(value: float) -> float:
    return float(f"{value:.12g}")


def _json_float(value: float | None) -> float | None:
    """JSON has no infinity or NaN: those are written as null."""
    if value is None or not math.isfinite(value):
        return None
    return _r(value)
