"""The repairer: a nominal plan made robust by placing fixtures (thesis Figures 4-6, 4-7).

:func:`repair_plan` turns every push of a nominal plan (:mod:`arrange_up.repair.nominal`)
into ``place(fixture), push, pick(fixture)``, choosing where the fixture goes and how far the
push drives so that the rest of the nominal plan reaches the goal from as much of the particle
belief as possible, the closeness to the nominal trajectory ("control along the trajectory",
§4.1.1) breaking ties::

    from arrange_up.io.domains import load
    from arrange_up.repair import nominal_plans, repair_plan

    problem = load("tz-mating")
    nominal = nominal_plans(problem, 1, seed=0)[0]
    result = repair_plan(problem, nominal, particles=150, seed=0, method="enhanced", workers=2)
    result.status, result.actions, result.steps[0].multiplier

The algorithm
=============
**Multi-step repair** (Figure 4-7). The nominal states ``x_0 .. x_n`` come from the nominal plan
in the deterministic semantics; the belief ``b_0`` is the particle semantics' initial belief
(:class:`~arrange_up.transitions.particles.ParticleSemantics`, ``particles`` and ``seed``).
Step by step, a place or pick action is kept as it is; a push is replaced by the solution of
its one-step fixture problem; the belief is propagated through what replaced it. When
propagation fails (every candidate of a push makes some particle leave the table or never come
to rest) the repair stops with status ``"failed"`` and a reason naming the step: an honest
failure, never a silently unreliable plan.

**One-step fixture problem** (Figures 4-6, 4-8 to 4-10), for push ``u_i`` from belief ``b_i``
(the candidates and their scores: :mod:`arrange_up.repair.candidates`):

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
4. *Push distance* (OPTIMIZEPUSHDISTANCE): the best :data:`REFINE` placements (of those that
   keep the plan nominal at some multiplier, item 6), the *stops* (fixtures flush with a moved
   part's nominal end along the axis its end is uncertain, on the placement grid:
   :func:`~arrange_up.repair.candidates.stop_placements`) and "no fixture" are simulated at
   every multiplier of :data:`MULTIPLIERS` (1, 1.25, 1.5, 1.75, 2; the push keeps its
   approach pose, only its distance grows). Each valid pair that may win is scored by its
   *reliability*: the share of rollouts of the nominal plan's remaining actions from its
   outcome that reach the goal, with common random numbers across the pairs
   (:mod:`arrange_up.repair.reliability`). The most reliable wins, the distance breaking ties
   (then the smaller multiplier). A fixture must be more reliable than the best bare push, or
   as reliable and closer by more than :data:`MIN_FIXTURE_GAIN` (1%, at least 0.01 in): a
   fixture the parts never touch changes the simulation only by round-off, and placing it
   would add two actions and a place's risk for nothing. The thesis optimised the multiplier
   for the one best placement by distance; the distance does not track what a fixture is for
   (a stop that makes a part's end certain can leave it farther from the nominal state on
   average), hence the reliability.
5. The push becomes ``place(fixture, pose), push(distance * multiplier), pick(fixture)``, or
   ``push(distance * multiplier)`` without a fixture.
6. *The plan stays a nominal plan* (:class:`PlanGuard`). A candidate may be refined or win
   only if the repaired steps so far, its own actions and the nominal plan's remaining
   actions, run in the deterministic semantics, leave every action applicable and (when the
   given plan reaches the goal) reach the goal. Candidates are checked lazily, best first, so
   the winner is the best candidate on the belief that keeps the plan valid; a step whose
   valid candidates all break it fails, naming why. Scoring the belief alone, a fixture or a
   longer push that stops the particles' spread could also move the nominal trajectory out of
   the goal, and the repair only found out at the end.

Noise and work sharing
======================
* *Common random numbers.* Particle ``i`` draws its noise at step ``k`` from the particle
  semantics' :meth:`~arrange_up.transitions.particles.ParticleSemantics.common_noise` (one
  place draw and one push draw: pose offsets, friction, densities), the same for every
  candidate of the step. Candidates are then compared on the same worlds, which removes most
  of the noise from their ranking with few particles; the belief propagation is the same
  simulation as the scoring.
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
* *Parallelism.* Particles of every candidate are split among ``workers`` processes, all
  candidates of a stage in one batch (the particle semantics' batch face,
  :meth:`~arrange_up.transitions.particles.ParticleSemantics.simulate_pushes`).

Statuses (:class:`~arrange_up.repair.records.RepairStatus`): ``"solved"`` (every step
repaired; ``actions`` is the repaired plan), ``"failed"`` (a step could not be propagated;
``reason`` says which and why), ``"timeout"``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import Any

import numpy as np

from arrange_up.belief.states import IntervalBelief, ObjectInterval, ParticleBelief
from arrange_up.counts import check_count
from arrange_up.geometry import shapes as geometry
from arrange_up.model.problem import ArrangementProblem, Pose
from arrange_up.model.world import Action, Pick, Place, Push, WorldState
from arrange_up.repair.candidates import (
    MULTIPLIERS,
    REFINE,
    SELECTION_MULTIPLIER,
    Candidate,
    Key,
    Outcome,
    StepScores,
    Swath,
    candidate,
    choose,
    clear_approach,
    footprint,
    grid_placements,
    mean_distance,
    normalise,
    part_swaths,
    round_pose_value,
    stage_candidates,
    stop_placements,
)
from arrange_up.repair.nominal import NominalReplay
from arrange_up.repair.records import (
    FAILED,
    SOLVED,
    TIMEOUT,
    RepairResult,
    StepRecord,
    StepRepairStatus,
    plan_groups,
)
from arrange_up.repair.reliability import RemainingPlan
from arrange_up.transitions.particles import DeterministicSemantics, ParticleSemantics

__all__ = ["DEFAULT_PARTICLES", "METHODS", "Repairer", "repair_plan", "step_scores"]

METHODS = ("naive", "enhanced")
#: Default particles (the thesis's Figure 4-14 setting).
DEFAULT_PARTICLES = 150

ProgressCallback = Callable[[dict[str, Any]], None]


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
    fixtures: bool = True,
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
    fixtures
        ``False``: the ablation of the fixtures. The repair runs as with fixtures but no
        placement is ever a candidate (every push's placement grid is empty), so each push
        keeps only the no-fixture candidates: the cleared approach's back-off and the push
        multipliers. Comparing its plan with the full repair's measures what the fixtures
        themselves bring. Recorded as ``fixtures`` in the result and its plan document.

    A repaired plan must reach the goal in the deterministic semantics. When the nominal plan
    does, every step keeps only candidates with which it still does (see the module
    docstring, item 6); a nominal plan that does not (an empty plan, or one short of the goal)
    is repaired as it is and ends with status ``"failed"`` and a ``reason`` naming the parts
    that miss the goal.
    Raises ``ValueError`` for bad arguments, or a nominal plan that fails in the deterministic
    semantics (it is not a nominal plan of ``problem``).
    """
    started = time.monotonic()
    deadline = None if timeout is None else started + timeout
    actions = tuple(actions)
    repairer = Repairer(problem, particles, seed, method, workers, deadline, fixtures=fixtures)
    records: list[StepRecord] = []
    out: list[Action] = []

    def result(status, plan, reason: str = "", beliefs=()) -> RepairResult:
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
            fixtures=fixtures,
        )

    try:
        states = repairer.nominal_states(actions)
        # the plan must stay a nominal plan step by step: applicable, and reaching the goal
        # when the given plan does (a plan short of the goal is repaired as it is, and fails
        # at the end)
        reaches_goal = not repairer.replay.goal_miss(states[-1])
        nominal = repairer.replay.initial()
        belief = repairer.initial_belief()
        beliefs = [belief]
        for index, action in enumerate(actions):
            step_started = time.monotonic()
            sims_before = repairer.simulations
            if isinstance(action, Push):
                guard = PlanGuard(repairer.replay, nominal, index, actions, reaches_goal)
                scores = repairer.one_step(
                    belief,
                    index,
                    action,
                    states[index],
                    states[index + 1],
                    progress,
                    len(actions),
                    guard=guard,
                    remaining=RemainingPlan(repairer, actions, index),
                )
                record = StepRecord.of_push(index, action, scores)
                after = scores.after
            else:
                after, reason = repairer.propagate(belief, index, (action,))
                record = StepRecord(
                    index,
                    type(action).__name__.lower(),
                    action,
                    (action,),
                    status=StepRepairStatus.OK if after is not None else StepRepairStatus.FAILED,
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
            nominal, why = repairer.replay.apply(nominal, record.actions)
            if nominal is None:  # the guard of the last push ran these very actions
                raise RuntimeError(f"step {index + 1} fails nominally after its check: {why}")
            if progress is not None:
                progress(
                    {
                        "step": index + 1,
                        "steps": len(actions),
                        "kind": record.kind,
                        "phase": "done",
                        "candidates": record.placements,
                        "elapsed": time.monotonic() - started,
                        "choice": record.describe_choice(problem),
                    }
                )
        missed = repairer.replay.goal_miss(nominal.particles[0])
        if missed:
            reason = f"the repaired plan does not reach the goal nominally: {missed}"
            return result(FAILED, None, reason, beliefs)
        return result(SOLVED, tuple(out), beliefs=beliefs)
    except _OutOfTime:
        return result(TIMEOUT, None, f"timeout of {timeout} s reached")
    finally:
        repairer.close()


class PlanGuard:
    """Whether a candidate of nominal step ``index`` keeps the repaired plan a nominal plan.

    ``nominal`` is the deterministic semantics' belief after the repaired steps before
    ``index``. A candidate is *rejected* (its reason returned, empty otherwise) when its
    actions followed by the nominal plan's remaining actions, run in the deterministic
    semantics, make an action fail or (with ``goal``) end outside the goal. When the next
    nominal action is a push and ``lookahead`` is set (the one-step problem sets it), that push
    is run as the next step's repair will first try it, which only the candidate's outcome on
    the belief tells (``lookahead(candidate, push)``: backed off the parts of that outcome),
    so that a choice does not leave the next step without a valid bare push. ``rejected``
    keeps every candidate's last refusal. Since every step's choice passes the check, the
    finished repair reaches the goal nominally.
    """

    def __init__(
        self,
        replay: NominalReplay,
        nominal: ParticleBelief,
        index: int,
        actions: Sequence[Action],
        goal: bool,
    ) -> None:
        self.replay = replay
        self.nominal = nominal
        self.index = index
        self.rest = [(k, (a,)) for k, a in enumerate(actions) if k > index]
        self.goal = goal
        self.lookahead: Callable[[Candidate, Push], Push] | None = None
        self.checked: dict[Key, str] = {}
        self._runs: dict[tuple[Any, ...], str] = {}

    def __call__(self, c: Candidate) -> str:
        group = c.actions()
        if c.fixture is not None and c.pose is not None and c.push is not None:
            # a fixture the nominal push does not reach leaves its outcome that of the bare
            # push (the same simulated bodies), and it is picked up again: the same run
            placed, _ = self.replay.apply(self.nominal, (Place(c.fixture, c.pose),))
            model = self.replay.model
            if placed is not None and c.fixture not in model.affected_objects(
                placed.intervals, c.push
            ):
                group = (c.push,)
        rest = self.rest
        if self.lookahead is not None and rest and isinstance(rest[0][1][0], Push):
            rest = [(rest[0][0], (self.lookahead(c, rest[0][1][0]),)), *rest[1:]]
        run = (group, rest[0][1] if rest else ())
        if run not in self._runs:
            self._runs[run] = self.replay.shortfall(
                self.nominal, [(self.index, group), *rest], goal=self.goal
            )
        self.checked[(c.fixture, c.pose, c.multiplier)] = self._runs[run]
        return self._runs[run]

    @property
    def rejected(self) -> tuple[tuple[Key, str], ...]:
        return tuple((key, why) for key, why in self.checked.items() if why)


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
    action number; for a repaired plan (see :func:`~arrange_up.repair.records.plan_groups`) the
    step number its ``repair.steps`` records, whose nominal plan, particles, seed and method
    are then the defaults, and whose earlier steps' repaired actions take the belief to the
    step, so the scores are the ones the repair saw (up to the rounding of numbers in the plan
    file). Without a repair record the defaults are 150 particles, seed 0, enhanced; a repair
    record of the fixtures' ablation (``fixtures`` false) scores no placement.

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
    fixtures = settings.get("fixtures", True) is not False
    repairer = Repairer(problem, particles, seed, method, workers, None, fixtures=fixtures)
    try:
        states = repairer.nominal_states(nominal)
        belief = repairer.initial_belief()
        deterministic = repairer.replay.initial()
        for k in range(step - 1):
            after, reason = repairer.propagate(belief, k, groups[k])
            if after is None:
                raise ValueError(f"the belief cannot be propagated through step {k + 1}: {reason}")
            belief = after
            deterministic, reason = repairer.replay.apply(deterministic, groups[k])
            if deterministic is None:
                raise ValueError(f"step {k + 1} fails in the deterministic semantics: {reason}")
        goal = not repairer.replay.goal_miss(states[-1])
        guard = PlanGuard(repairer.replay, deterministic, step - 1, nominal, goal)
        return repairer.one_step(
            belief,
            step - 1,
            push,
            states[step - 1],
            states[step],
            guard=guard,
            remaining=RemainingPlan(repairer, nominal, step - 1),
        )
    finally:
        repairer.close()


class _OutOfTime(Exception):
    pass


class Repairer:
    """State shared by the steps of one repair: the problem, the particle semantics (its
    propagation, common random numbers and worker pool) and the deadline. With
    ``fixtures=False`` no placement is a candidate (see :func:`repair_plan`)."""

    def __init__(
        self,
        problem: ArrangementProblem,
        particles: int,
        seed: int,
        method: str,
        workers: int,
        deadline: float | None,
        *,
        fixtures: bool = True,
    ) -> None:
        if method not in METHODS:
            raise ValueError(f"unknown method {method!r}; expected one of {', '.join(METHODS)}")
        check_count("particles", particles)
        check_count("seed", seed, minimum=None)
        check_count("workers", workers)
        self.problem = problem
        self.particles = particles
        self.seed = seed
        self.method = method
        self.workers = workers
        self.deadline = deadline
        self.fixtures = fixtures
        self.semantics = ParticleSemantics(problem, particles=particles, seed=seed, workers=workers)
        self.checker = self.semantics.checker
        self.frame = self.semantics.frame
        self.simulations = 0
        self.parts = tuple(spec.name for spec in problem.parts)
        self.replay = NominalReplay(problem)
        self._intervals: dict[int, tuple[ParticleBelief, IntervalBelief]] = {}

    # -- setup ---------------------------------------------------------------------------------
    def initial_belief(self) -> ParticleBelief:
        return self.semantics.initial_belief()

    def nominal_states(self, actions: Sequence[Action]) -> list[WorldState]:
        """``x_0 .. x_n`` of the nominal plan in the deterministic semantics."""
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

    def close(self) -> None:
        self.semantics.close()
        self.replay.close()

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

    # -- propagation with the step's common random numbers --------------------------------------
    def place(self, belief: ParticleBelief, step: int, place: Place) -> ParticleBelief:
        if any(place.obj in state.names() for state in belief.particles):
            raise ValueError(f"place: {place.obj!r} is already on the table")
        offsets = [noise.pose_offset for noise, _ in self.semantics.common_noise(step)]
        return self.semantics.place_particles(belief, place, offsets)

    def pick(self, belief: ParticleBelief, pick: Pick) -> ParticleBelief:
        # the angles stay as the place or push left them (not wrapped again): the repair's
        # beliefs, and so its choices, have always been computed so
        return self.semantics.pick_particles(belief, pick, canonical=False)

    def propagate(
        self, belief: ParticleBelief, step: int, group: Sequence[Action]
    ) -> tuple[ParticleBelief | None, str]:
        """Apply a group of actions (one nominal step's replacement) with step ``step``'s noise."""
        for action in group:
            if isinstance(action, Place):
                belief = self.place(belief, step, action)
            elif isinstance(action, Pick):
                belief = self.pick(belief, action)
            elif isinstance(action, Push):
                [result] = self.pushes([(belief, action)], step)
                if result.belief is None:
                    return None, result.reason
                belief = result.belief
            else:
                raise TypeError(f"not an action: {action!r}")
        return belief, ""

    def pushes(
        self,
        batch: Sequence[tuple[ParticleBelief, Push]],
        step: int,
        *,
        distance_to: WorldState | None = None,
    ) -> list[Outcome]:
        """Simulate each ``(belief, push)`` of ``batch`` on every particle, in one batch.

        Only the objects the push's conservative sweep can reach are simulated; a worker stops
        its particles at the first failure (the outcome is invalid anyway). The outcome's
        belief is ``None`` when a particle failed; its distance is to ``distance_to`` (``nan``
        without it).
        """
        self._check_time()
        noises = [noise for _, noise in self.semantics.common_noise(step)]
        affected = [self.semantics.affected_objects(self.intervals(b), p) for b, p in batch]
        groups = [
            self.semantics.push_jobs(b, p, a, noises)
            for (b, p), a in zip(batch, affected, strict=True)
            if a
        ]
        simulated = iter(self.semantics.simulate_pushes(groups, stop_on_failure=True))
        outcomes = []
        for (belief, _push), reach in zip(batch, affected, strict=True):
            if not reach:
                after = belief
            else:
                pushed = next(simulated)
                self.simulations += pushed.simulated
                if pushed.failure is not None:
                    outcomes.append(Outcome(None, math.inf, pushed.failure.reason()))
                    continue
                after = self.semantics.moved_particles(belief, pushed.outcomes)
            distance = math.nan if distance_to is None else self.distance(after, distance_to)
            outcomes.append(Outcome(after, distance))
        return outcomes

    def raw_poses(
        self, belief: ParticleBelief, push: Push, step: int
    ) -> tuple[list[dict[str, Pose]], str]:
        """Every particle's poses after ``push`` even when some fail (for the swath), and the
        first failure's reason ("" when none failed)."""
        self._check_time()
        poses: list[dict[str, Pose]] = [dict(s.poses) for s in belief.particles]
        affected = self.semantics.affected_objects(self.intervals(belief), push)
        if not affected:
            return poses, ""
        noises = [noise for _, noise in self.semantics.common_noise(step)]
        jobs = self.semantics.push_jobs(belief, push, affected, noises)
        [pushed] = self.semantics.simulate_pushes([jobs], stop_on_failure=False)
        self.simulations += pushed.simulated
        for particle, outcome in zip(poses, pushed.outcomes, strict=True):
            assert outcome is not None
            particle.update(outcome.poses)
        return poses, "" if pushed.failure is None else pushed.failure.reason()

    def distance(self, belief: ParticleBelief, nominal: WorldState) -> float:
        """The mean distance of ``belief``'s parts from ``nominal`` (see
        :func:`~arrange_up.repair.candidates.mean_distance`)."""
        return mean_distance(belief, nominal, self.parts)

    # -- the one-step fixture problem ---------------------------------------------------------
    def one_step(
        self,
        belief: ParticleBelief,
        step: int,
        push: Push,
        state: WorldState,
        nominal_next: WorldState,
        progress: ProgressCallback | None = None,
        steps: int = 0,
        *,
        guard: PlanGuard | None = None,
        remaining: RemainingPlan | None = None,
    ) -> StepScores:
        """ONESTEPFIXTUREPROBLEM (Figure 4-6) for ``push`` from ``belief``.

        With a ``guard``, only candidates it accepts are refined and may win: the best few
        placements are the best that keep the plan nominal at some multiplier, and the winner
        the best candidate that keeps it so (see :class:`PlanGuard`). With ``remaining`` (the
        nominal plan's actions after this push), the refined candidates are ranked by their
        reliability (:mod:`arrange_up.repair.reliability`), the distance breaking ties;
        without it, by the distance alone."""
        started = time.monotonic()
        sims_before = self.simulations

        def report(phase: str, candidates: int) -> None:
            if progress is not None:
                progress(
                    {
                        "step": step + 1,
                        "steps": steps,
                        "kind": "push",
                        "phase": phase,
                        "candidates": candidates,
                        "elapsed": time.monotonic() - started,
                    }
                )

        problem = _OneStepProblem(self, belief, step, push, nominal_next)
        if guard is not None:
            guard.lookahead = problem.next_push
        # 1. swath from the no-fixture push at the selection multiplier (every particle)
        swaths = problem.swaths()
        grid = problem.grid(swaths)
        allowed = [g for g in grid if g[2]]
        report("placements", len(allowed) + 1)
        # 2-3. placements at the selection multiplier (falling back to smaller ones)
        selection = SELECTION_MULTIPLIER
        for m in sorted(MULTIPLIERS, reverse=True):
            selection = m
            keys = [(None, None, m)] + [(f, p, m) for f, p, _ in allowed]
            problem.evaluate(keys)
            if any(problem.outcomes[key].belief is not None for key in keys):
                break
        placement_candidates = stage_candidates(
            [(None, None, True)] + grid, selection, problem.outcomes, problem.pushed
        )
        # 4. multipliers for the best few placements (that keep the plan nominal at some
        # multiplier) and no fixture
        ranked: list[Candidate] = []
        for c in sorted(
            (c for c in placement_candidates if c.valid and c.fixture is not None and c.reachable),
            key=lambda c: c.distance,
        ):
            if len(ranked) == REFINE:
                break
            if guard is None or any(
                not guard(replace(c, multiplier=m, push=problem.pushed(m))) for m in MULTIPLIERS
            ):
                ranked.append(c)
        bare_keys: list[Key] = [(None, None, m) for m in MULTIPLIERS]
        problem.evaluate(bare_keys)
        # 5. stops where the bare push leaves a part's end uncertain
        stops = [
            (f, p)
            for f, p, ok in problem.stops()
            if ok and all((f, p) != (c.fixture, c.pose) for c in ranked)
        ]
        report("refine", (len(ranked) + len(stops) + 1) * len(MULTIPLIERS))
        refine_keys = bare_keys + [
            (f, p, m) for f, p in [(c.fixture, c.pose) for c in ranked] + stops for m in MULTIPLIERS
        ]
        problem.evaluate(refine_keys)
        stop_set = set(stops)
        refined = normalise(
            [
                replace(
                    candidate(key, problem.outcomes[key], problem.pushed(key[2])),
                    stop=(key[0], key[1]) in stop_set,
                )
                for key in refine_keys
            ]
        )
        # 6. reliability of every valid candidate that may win (bare pushes always: they are
        # the bar a fixture must clear)
        if remaining is not None:
            refined = [
                replace(c, reliability=remaining.reliability(outcome))
                if c.valid
                and (outcome := problem.outcomes[(c.fixture, c.pose, c.multiplier)].belief)
                is not None
                and (c.fixture is None or not c.reachable or guard is None or not guard(c))
                else c
                for c in refined
            ]
        best = choose([c for c in refined if c.valid], guard)
        after = None
        if best is not None:
            after = problem.outcomes[(best.fixture, best.pose, best.multiplier)].belief
        return StepScores(
            step=step,
            push=push,
            backoff=problem.backoff,
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
            rejected=() if guard is None else guard.rejected,
        )


class _OneStepProblem:
    """The one-step fixture problem of one push from one belief: its backed-off push, and
    every candidate simulated so far (``outcomes``, by key), each simulated once."""

    def __init__(
        self,
        repairer: Repairer,
        belief: ParticleBelief,
        step: int,
        push: Push,
        nominal_next: WorldState,
    ) -> None:
        self.repairer = repairer
        self.belief = belief
        self.step = step
        self.push = push
        self.nominal_next = nominal_next
        self.approach, self.backoff = clear_approach(
            repairer.problem, repairer.checker, repairer.intervals(belief), push
        )
        self.outcomes: dict[Key, Outcome] = {}

    def pushed(self, multiplier: float) -> Push:
        """The push from the cleared approach, its distance times ``multiplier`` plus the
        back-off."""
        push = self.push
        distance = round_pose_value(push.distance * multiplier + self.backoff)
        return Push(push.manipulator, self.approach, distance)

    def next_push(self, c: Candidate, push: Push) -> Push:
        """The next nominal ``push`` as the next step's repair first tries it after candidate
        ``c``: backed off the parts of ``c``'s outcome on the belief (as given while that
        outcome is not simulated, or failed)."""
        outcome = self.outcomes.get((c.fixture, c.pose, c.multiplier))
        if outcome is None or outcome.belief is None:
            return push
        r = self.repairer
        approach, backoff = clear_approach(r.problem, r.checker, r.intervals(outcome.belief), push)
        return Push(push.manipulator, approach, round_pose_value(push.distance + backoff))

    def swaths(self) -> tuple[Swath, ...]:
        """The part motion swaths of the no-fixture push at the selection multiplier, whose
        outcome (on every particle, also when some fail) is kept as that candidate's."""
        r, belief = self.repairer, self.belief
        raw, failure = r.raw_poses(belief, self.pushed(SELECTION_MULTIPLIER), self.step)
        swaths = part_swaths(r.checker, r.parts, belief, raw)
        key = (None, None, SELECTION_MULTIPLIER)
        if failure:
            self.outcomes[key] = Outcome(None, math.inf, failure)
        else:
            bare = ParticleBelief(
                tuple(r.frame.canonical(WorldState.from_mapping(r.problem, p)) for p in raw)
            )
            self.outcomes[key] = Outcome(bare, r.distance(bare, self.nominal_next))
        return swaths

    def stops(self) -> list[tuple[str, Pose, bool]]:
        """The stop placements of the bare push at 1x (:func:`stop_placements`); none
        without fixtures or when that push fails."""
        r, belief = self.repairer, self.belief
        outcome = self.outcomes.get((None, None, 1.0))
        if not r.fixtures or outcome is None or outcome.belief is None:
            return []
        return stop_placements(
            r.problem,
            r.checker,
            r.intervals(belief),
            belief.names(),
            self.pushed(1.0),
            belief,
            outcome.belief,
            self.nominal_next,
            r.parts,
        )

    def grid(self, swaths: tuple[Swath, ...]) -> list[tuple[str, Pose, bool]]:
        """The placement grid (``(fixture, pose, allowed)``); for the enhanced method only the
        placements whose footprint meets a swath; empty without fixtures."""
        r, belief = self.repairer, self.belief
        if not r.fixtures:
            return []
        grid = grid_placements(
            r.problem, r.checker, r.intervals(belief), belief.names(), self.pushed(1.0)
        )
        if r.method != "enhanced":
            return grid
        return [
            g
            for g in grid
            if any(
                geometry.boxes_overlap(footprint(r.checker, g[0], g[1]), box) for _, box in swaths
            )
        ]

    def evaluate(self, keys: list[Key]) -> None:
        """Simulate the candidates of ``keys`` not yet simulated (no fixture first)."""
        r, belief, step, outcomes = self.repairer, self.belief, self.step, self.outcomes
        todo = [key for key in keys if key not in outcomes]
        bare = [key for key in todo if key[0] is None]
        if bare:
            results = r.pushes(
                [(belief, self.pushed(m)) for _, _, m in bare],
                step,
                distance_to=self.nominal_next,
            )
            outcomes.update(zip(bare, results, strict=True))
        batch, batch_keys = [], []
        for key in todo:
            fixture, pose, m = key
            if fixture is None or pose is None:
                continue
            placed = r.place(belief, step, Place(fixture, pose))
            affected = r.semantics.affected_objects(r.intervals(placed), self.pushed(m))
            if fixture not in affected:
                base = outcomes[(None, None, m)]
                outcomes[key] = Outcome(base.belief, base.distance, base.reason, reachable=False)
                continue
            batch.append((placed, self.pushed(m)))
            batch_keys.append(key)
        if batch:
            results = r.pushes(batch, step)
            for key, result in zip(batch_keys, results, strict=True):
                if result.belief is not None:
                    after = r.pick(result.belief, Pick(key[0]))  # type: ignore[arg-type]
                    result = Outcome(after, r.distance(after, self.nominal_next))
                outcomes[key] = result
