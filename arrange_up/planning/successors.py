"""Successor evaluation of a planning run: staged, and in parallel on a runner.

The search (:func:`arrange_up.search.best_first_search`) decides, one edge at a time, which
successor belief to compute next; :class:`SuccessorEvaluator` computes them.

Staged pushes (less wasted simulation)
--------------------------------------
Dominance (:class:`~arrange_up.belief.states.IntervalDominanceIndex`) prunes a belief when a
stored belief's box lies inside its own. The box of some of a child's particles lies inside
the box of all of them, so if a belief of some particles after a push is already dominated,
the whole child is too, and its other particles need not be simulated. A push is therefore
computed in two shares: first the particles at the least or greatest value of some pose
coordinate of a pushed object in the *parent* (:func:`first_share`: the particles likeliest
to span the child's box; a dominated child's box is usually within the tolerance of its
dominator's, so a share of arbitrary particles rarely shows it), then the dominance test,
then, unless dominated, the rest. The test runs when the search evaluates the edge, against
the index as the search has it then, so the search discards exactly the children it would
have discarded anyway: plans are unchanged (the child counts as ``pruned_dominated``, where a
full simulation might have found it a duplicate or refused it, discarded just the same), and
``transitions_simulated`` counts the particles simulated.

Parallel successors
-------------------
With a runner of more than one worker, or a Dask one (:func:`arrange_up.parallel.get_runner`),
the search tells the evaluator which edges it will evaluate next
(:meth:`SuccessorEvaluator.prefetch`) and the workers simulate the pushes among them (with
the heuristic value of a push simulated whole; a staged push's two shares run side by side)
while the search deals with the current edge. Places and picks cost less than a round trip
and are computed here when asked for, as is a push asked for before a worker started on it
(rather than queued behind work sent ahead); at most one job per worker is in flight. A child
is a function of the parent belief, the action and the run's seed only (see
:mod:`arrange_up.transitions.particles`), so which process computes it, and whether it was
computed ahead, changes nothing: the search makes the same decisions in the same order, and
plans and statistics are identical for any worker count and backend. The problem, and the task
each worker builds from it, travel to each worker once (a :class:`~arrange_up.parallel.Session`);
a job carries a belief and an action. Pushes computed ahead that the search never asks for are
wasted work (not in the run's statistics; :attr:`SuccessorEvaluator.sent` counts the jobs).

Why a child has no prediction travels the same way as the simulations it took: a job's answer
carries the reasons its semantics counted while computing it (its ``reasons``, as CBST's and
the particle semantics' name them), and :attr:`SuccessorEvaluator.reasons` adds up those of
the children the search asked for, the same for any runner.
"""

from __future__ import annotations

import threading
from collections import Counter, deque
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

from arrange_up.belief.compiled import CompiledProblem
from arrange_up.belief.states import IntervalDominanceIndex, ParticleBelief
from arrange_up.model.world import Push
from arrange_up.parallel import Pending, Runner, SerialRunner, Session
from arrange_up.planning.config import PlanConfig
from arrange_up.planning.task import BeliefTask
from arrange_up.search import DOMINATED, Edge
from arrange_up.transitions.particles import ParticleSemantics

__all__ = ["FIRST_SHARE", "SuccessorEvaluator", "WorkerSpec", "first_share"]

#: Most particles, as a fraction of a belief's, that a staged push simulates first.
FIRST_SHARE = 0.5
#: Jobs in the workers' hands at once, per worker: one running, none queued, so a job the
#: search asks for is never queued behind work sent ahead (it is computed here instead).
AHEAD_PER_WORKER = 1
#: Children computed ahead and not yet asked for that are kept; older ones are dropped (and
#: computed again if asked for), so a long search does not hoard unread beliefs.
KEPT_AHEAD = 2048


def first_share(belief: ParticleBelief, affected: frozenset[str]) -> tuple[int, ...]:
    """The particles simulated first in a staged push of ``belief`` moving ``affected``: those
    at the least or the greatest value of some pose coordinate of an affected object, in
    particle order (the particles likeliest to span the child's box), or none (no staging)
    when they are more than :data:`FIRST_SHARE` of the particles."""
    names = belief.names()
    columns = [j for j, name in enumerate(names) if name in affected]
    poses = belief.poses[:, columns, :].reshape(belief.poses.shape[0], -1)
    chosen: dict[int, None] = {}
    for extreme in (poses.argmin(axis=0), poses.argmax(axis=0)):
        chosen.update((int(i), None) for i in extreme)
    if len(chosen) > FIRST_SHARE * belief.poses.shape[0]:
        return ()
    return tuple(sorted(chosen))


@dataclass(eq=False)
class WorkerSpec:
    """What a worker needs to build the run's :class:`BeliefTask` (shipped once per worker;
    the task is built on first use and kept with the unpickled spec; the compiled problem
    travels as its problem and is compiled again in the worker)."""

    compiled: CompiledProblem
    config: PlanConfig
    _task: BeliefTask | None = field(default=None, repr=False)
    _lock: Any = field(default=None, repr=False)

    def __post_init__(self) -> None:
        self._lock = threading.Lock()

    def __getstate__(self) -> dict[str, Any]:
        return {**self.__dict__, "_task": None, "_lock": None}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self.__dict__.update(state, _lock=threading.Lock())

    def task(self) -> BeliefTask:
        if self._task is None:
            # a worker only resolves transitions and heuristic values: no dominance, and the
            # pushes it is given are already varied
            config = PlanConfig.of(self.config, dominance=False, variety=False)
            self._task = BeliefTask.build(self.compiled, config)
        return self._task

    def lock(self) -> Any:
        # a threaded Dask worker runs tasks side by side in one process: one at a time here
        return self._lock


class _InProcess:
    """The context of a serial session: the planner's own task (nothing is pickled)."""

    def __init__(self, task: BeliefTask) -> None:
        self._task = task
        self._lock = threading.Lock()

    def task(self) -> BeliefTask:
        return self._task

    def lock(self) -> Any:
        return self._lock


@dataclass(frozen=True)
class _Answer:
    """A job's result: the child (None: no prediction) and its heuristic value when asked
    for (``whole``), or a share's :class:`~arrange_up.transitions.particles.PushBatch`
    (``share``); the simulations run, and the ``(reason, count)`` of the refusals the
    semantics counted in its ``reasons`` meanwhile (empty for a semantics without them)."""

    child: Any
    h: float | None
    batch: Any
    simulations: int
    reasons: tuple[tuple[str, int], ...] = ()


def _work(context: Any, job: tuple[Any, ...]) -> _Answer:
    """Worker side: one job of :class:`_Child`: ``("whole", belief, action, with_h)`` or
    ``("share", belief, action, indices, affected)``."""
    with context.lock():
        task = context.task()
        semantics = task.semantics
        before = semantics.simulations
        counted: Counter[str] | None = getattr(semantics, "reasons", None)
        known = Counter(counted) if counted else Counter()
        if job[0] == "whole":
            _, belief, action, with_h = job
            child = semantics.apply(belief, action)
            h = float(task.heuristic(child)) if with_h and child is not None else None
            batch = None
        else:
            _, belief, action, indices, affected = job
            batch, _ = semantics.push_share(belief, action, indices, affected)
            child = h = None
        # the refusals counted by this job alone (counts only grow)
        reasons = tuple((counted - known).items()) if counted is not None else ()
        return _Answer(child, h, batch, semantics.simulations - before, reasons)


class _Child:
    """``make_child`` of one edge: computes the child through the evaluator's sessions and
    answers the search with it, None (no prediction) or :data:`DOMINATED`.

    A push of a particle semantics that reaches something, with a small enough
    :func:`first_share`, is staged: two ``share`` jobs, the first share and the rest, sent
    together (a serial session computes the rest only if asked; workers compute both side by
    side); when the search asks, the first share's box is tested, and the rest is read only
    if it is not dominated. Anything else is one ``whole`` job: on the runner for a push, here
    for a place or a pick (they cost less than a round trip).
    """

    __slots__ = ("action", "belief", "done", "evaluator", "jobs", "shares")

    def __init__(self, evaluator: SuccessorEvaluator, belief: Any, action: Any) -> None:
        self.evaluator, self.belief, self.action = evaluator, belief, action
        self.jobs: list[Pending[_Answer]] = []
        self.shares: tuple[tuple[int, ...], tuple[int, ...], frozenset[str]] | None = None
        self.done = False

    def sent(self) -> bool:
        return bool(self.jobs)

    def send(self, here: bool = False) -> None:
        """Send this edge's jobs (a no-op once sent): pushes to the runner, unless ``here``."""
        if self.jobs:
            return
        ev = self.evaluator
        if not isinstance(self.action, Push):
            self.jobs = [ev.here.submit(("whole", self.belief, self.action, False))]
            return
        remote = ev.here if here else ev.session
        if ev.staged:
            semantics = ev.task.semantics
            affected = semantics.affected_objects(self.belief.intervals, self.action)
            first = first_share(self.belief, affected) if affected else ()
            if first:
                chosen = set(first)
                rest = tuple(i for i in range(len(self.belief.poses)) if i not in chosen)
                self.shares = (first, rest, affected)
                self.jobs = [
                    remote.submit(("share", self.belief, self.action, part, affected))
                    for part in (first, rest)
                ]
                ev.sent += 2
                return
        self.jobs = [remote.submit(("whole", self.belief, self.action, ev.ahead and not here))]
        ev.sent += 1

    def reset(self) -> None:
        """Forget the jobs (cancelled if not started): sent again if the search asks."""
        for job in self.jobs:
            job.cancel()
        self.jobs, self.shares = [], None

    def __call__(self) -> Any:
        ev = self.evaluator
        if self.jobs and not any(job.done() for job in self.jobs) and self.jobs[0].withdraw():
            # asked for before a worker took it: this process computes it rather than wait
            # for it behind work sent ahead (a later job taken meanwhile is just wasted)
            for job in self.jobs[1:]:
                job.cancel()
            self.jobs, self.shares = [], None
        # not sent ahead (or withdrawn): computed here, as with one worker
        self.send(here=True)
        self.done = True
        jobs, self.jobs = self.jobs, []
        first = jobs[0].result()
        ev.count(first)
        if self.shares is None:
            ev.last = (first.child, first.h)
            return first.child
        indices, rest, affected = self.shares
        self.shares = None
        semantics = ev.task.semantics
        if not first.batch.ok:
            jobs[1].cancel()
            return None
        outcomes = dict(zip(indices, first.batch.outcomes, strict=True))
        # the particles outside the share stand in with the share's first particle's pushed
        # objects: this belief's box is the share's for those objects and, exactly, the full
        # child's for the others (canonical angles are wrapped object by object)
        stand_in = first.batch.outcomes[0]
        box = semantics.moved_particles(
            self.belief, [outcomes.get(i, stand_in) for i in range(len(self.belief.poses))]
        )
        # the test runs now, against the index as the search has it now (module doc)
        if ev.dominated(box):
            jobs[1].cancel()
            return DOMINATED
        second = jobs[1].result()
        ev.count(second)
        if not second.batch.ok:
            return None
        outcomes.update(zip(rest, second.batch.outcomes, strict=True))
        return semantics.moved_particles(self.belief, [outcomes[i] for i in sorted(outcomes)])


class SuccessorEvaluator:
    """Computes the search's successor beliefs for one planning run (see the module doc).

    ``runner`` runs the jobs (a serial runner: here, each when the search asks for it);
    ``spec`` is what the workers build their task from (ignored by a serial runner, which uses
    ``task``); ``index`` is the search's dominance index (None: no staged pushes).
    :attr:`simulations` counts the simulations of the children the search asked for, the
    same for any runner, and :attr:`reasons` why the semantics refused those it refused (its
    ``reasons``, counted in whichever process computed them); :attr:`sent` counts the jobs
    sent, among them those computed ahead that the search never asked for.
    """

    def __init__(
        self,
        task: BeliefTask,
        runner: Runner,
        spec: WorkerSpec,
        index: IntervalDominanceIndex | None,
    ) -> None:
        self.task = task
        self.runner = runner
        self.index = index
        self.staged = (
            index is not None
            and isinstance(task.semantics, ParticleSemantics)
            and task.semantics.particles > 2
        )
        # a Dask cluster of one worker is still another machine's core to use
        self.ahead = runner.workers > 1 or runner.backend == "dask"
        here = _InProcess(task)
        # places and picks are computed here, pushes (the physics) on the runner
        self.here: Session[tuple[Any, ...], _Answer] = SerialRunner().session(_work, here)
        self.session = runner.session(_work, spec) if self.ahead else self.here
        self.simulations = 0
        self.reasons: Counter[str] = Counter()
        self.sent = 0
        self.last: tuple[Any, float | None] | None = None
        self._sent: deque[_Child] = deque()
        self._ahead: deque[_Child] = deque()

    # -- what the search calls -----------------------------------------------------------------
    def successors(self, belief: Any) -> Iterator[Edge[Any, Any]]:
        """The task's edges of ``belief``, each computed through this evaluator."""
        for edge in self.task.successors(belief):
            yield Edge(edge.action, edge.cost, _Child(self, belief, edge.action))

    def heuristic(self, belief: Any) -> float:
        """The task's heuristic; for the child just computed by a worker, its value from there."""
        last, self.last = self.last, None
        if last is not None and last[0] is belief and last[1] is not None:
            return last[1]
        return self.task.heuristic(belief)

    def prefetch(self, edges: Sequence[Edge[Any, Any]]) -> None:
        """Send the pushes among ``edges`` (the next the search will evaluate, in order) to
        the workers while they have room; places and picks are left to be computed here."""
        room = AHEAD_PER_WORKER * self.runner.workers
        self._sent = deque(c for c in self._sent if not c.done)
        busy = sum(not job.done() for c in self._sent for job in c.jobs)
        for edge in edges:
            child = edge.make_child
            if busy >= room:
                break
            if not isinstance(child, _Child) or child.done or child.sent():
                continue
            if not isinstance(child.action, Push):
                continue
            child.send()
            busy += len(child.jobs)
            self._sent.append(child)
            self._ahead.append(child)
        while len(self._ahead) > KEPT_AHEAD:
            dropped = self._ahead.popleft()
            if not dropped.done:
                dropped.reset()

    # -- helpers ---------------------------------------------------------------------------------
    def count(self, answer: _Answer) -> None:
        """Add the simulations and the refusal reasons of an ``answer`` the search asked for."""
        self.simulations += answer.simulations
        self.reasons.update(dict(answer.reasons))

    def dominated(self, partial: ParticleBelief) -> bool:
        assert self.index is not None
        return self.index.dominated(partial, 0.0)

    def close(self) -> None:
        for child in self._sent:
            child.reset()
        if self.session is not self.here:
            self.session.close()
