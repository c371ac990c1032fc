"""Successor evaluation of a planning run: staged, and in parallel on a runner.

The search (:func:`arrange_up.search.best_first_search`) decides, one edge at a time, which
successor belief to compute next; :class:`SuccessorEvaluator` computes them.

Staged pushes (less wasted simulation)
--------------------------------------
Dominance (:class:`~arrange_up.belief.states.IntervalDominanceIndex`) prunes a belief when a
stored belief's box lies inside its own. The box of a few particles lies inside the box of
all of them, so if the belief of the first :func:`first_share` particles after a push is
already dominated, the whole child is too, and its other particles need not be simulated.
A push child is therefore computed in two shares: the first particles, the dominance test on
their belief, then (unless dominated) the rest. The test runs at the moment the search
evaluates the edge, against the index as the search has it then, so the search discards
exactly the children it would have discarded anyway: plans are unchanged (the search counts
the child as ``pruned_dominated``, where a full simulation might have found it a duplicate or
refused it, discarded just the same).

Parallel successors
-------------------
With a runner of more than one worker (:func:`arrange_up.parallel.get_runner`: local loky
processes or a Dask cluster), the search hands the evaluator the edges it will evaluate next
(:meth:`SuccessorEvaluator.prefetch`) and the workers compute those children, with their
heuristic values, while the search deals with the current one. A child is a function of the
parent belief, the action and the run's seed only (see :mod:`arrange_up.transitions.particles`),
so which worker computes it, and whether it was computed ahead, changes nothing: the search
makes the same decisions in the same order, and plans and statistics are identical for any
worker count and backend. The problem, and the task each worker builds from it, travel to
each worker once (a :class:`~arrange_up.parallel.Session`); a task carries a belief and an
action. Work computed ahead that the search never asks for is wasted (it is not in the run's
statistics; :attr:`SuccessorEvaluator.sent` counts the jobs sent).
"""

from __future__ import annotations

import threading
from collections import deque
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from arrange_up.belief.states import IntervalDominanceIndex, ParticleBelief
from arrange_up.model.problem import ArrangementProblem
from arrange_up.model.world import Push
from arrange_up.parallel import Pending, Runner, SerialRunner, Session
from arrange_up.planning.task import BeliefTask
from arrange_up.search import DOMINATED, Edge
from arrange_up.transitions.particles import ParticleSemantics

__all__ = ["FIRST_SHARE", "SuccessorEvaluator", "WorkerSpec", "first_share"]

#: Most particles, as a fraction of a belief's, that a staged push simulates first.
FIRST_SHARE = 0.5
#: Edges handed to the workers ahead, per worker.
AHEAD_PER_WORKER = 2
#: Children computed ahead and not yet asked for that are kept; older ones are dropped (and
#: computed again if asked for), so a long search does not hoard unread beliefs.
KEPT_AHEAD = 2048


def first_share(belief: ParticleBelief, affected: frozenset[str]) -> tuple[int, ...]:
    """The particles simulated first in a staged push of ``belief`` moving ``affected``: those
    at the least or the greatest value of some pose coordinate of an affected object, in
    coordinate order (the particles likeliest to span the child's box), or none (no staging)
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
    the task is built on first use and kept with the unpickled spec)."""

    problem: ArrangementProblem
    semantics: str
    particles: int
    seed: int
    heuristic: str
    model: str | Path | None = None
    _task: BeliefTask | None = field(default=None, repr=False)
    _lock: Any = field(default=None, repr=False)

    def __getstate__(self) -> dict[str, Any]:
        return {**self.__dict__, "_task": None, "_lock": None}

    def task(self) -> BeliefTask:
        if self._task is None:
            self._task = BeliefTask.build(
                self.problem,
                semantics=self.semantics,
                particles=self.particles,
                seed=self.seed,
                workers=1,
                heuristic=self.heuristic,
                dominance=False,
                variety=False,
                model=self.model,
            )
        return self._task

    def lock(self) -> Any:
        # a threaded Dask worker runs tasks side by side in one process: one at a time here
        if self._lock is None:
            self._lock = threading.Lock()
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
    """A job's result: the child (None: no prediction; for a first share, a belief whose box
    lies inside the child's), its heuristic value when asked for, for a first share what the
    rest needs (its particles, their outcomes, the pushed objects), and the simulations run."""

    child: Any
    h: float | None
    staged: tuple[Any, ...] | None
    simulations: int

    @property
    def partial(self) -> bool:
        return self.staged is not None


def _work(context: Any, job: tuple[Any, ...]) -> _Answer:
    """Worker side: one job of :class:`_Child` (``whole``, ``first`` or ``rest``)."""
    kind, belief, action, with_h, first = job
    with context.lock():
        task = context.task()
        semantics = task.semantics
        before = semantics.simulations
        staged: tuple[Any, ...] | None = None
        if kind == "whole":
            child = semantics.apply(belief, action)
        elif kind == "first":
            affected = semantics.affected_objects(belief.intervals, action)
            indices = first_share(belief, affected) if affected else ()
            if not indices:  # reaches nothing, or nothing to gain: the whole push at once
                child = semantics.apply(belief, action)
            else:
                batch, _ = semantics.push_share(belief, action, indices, affected)
                child = None
                if batch.ok:
                    # every particle outside the share stands in with the share's first
                    # particle's pushed objects: the box of this belief is the share's for the
                    # pushed objects and the full child's, exactly, for the others
                    outcomes = dict(zip(indices, batch.outcomes, strict=True))
                    stand_in = batch.outcomes[0]
                    full = [outcomes.get(i, stand_in) for i in range(belief.poses.shape[0])]
                    child = semantics.moved_particles(belief, full)
                    staged = (indices, batch.outcomes, affected)
        else:
            indices, outcomes, affected = first
            chosen = set(indices)
            rest = [i for i in range(belief.poses.shape[0]) if i not in chosen]
            batch, _ = semantics.push_share(belief, action, rest, affected)
            child = None
            if batch.ok:
                every = dict(zip(indices, outcomes, strict=True))
                every.update(zip(rest, batch.outcomes, strict=True))
                child = semantics.moved_particles(belief, [every[i] for i in sorted(every)])
        h = None
        if with_h and child is not None and staged is None:
            h = float(task.heuristic(child))
        return _Answer(child, h, staged, semantics.simulations - before)


class _Child:
    """``make_child`` of one edge: computes the child through the evaluator's session, in one
    job or two staged ones, and answers the search with it, None or :data:`DOMINATED`."""

    __slots__ = ("action", "belief", "done", "evaluator", "first", "pending", "stage")

    def __init__(self, evaluator: SuccessorEvaluator, belief: Any, action: Any) -> None:
        self.evaluator, self.belief, self.action = evaluator, belief, action
        self.stage = 0  # 0 nothing sent, 1 first share (or whole) sent, 2 rest sent
        self.pending: Pending[_Answer] | None = None
        self.first: _Answer | None = None
        self.done = False

    def staged(self) -> bool:
        return self.evaluator.staged and isinstance(self.action, Push)

    def send(self) -> None:
        """Send the next job of this edge (a no-op once it is sent)."""
        ev = self.evaluator
        remote = ev.ahead and isinstance(self.action, Push)
        if self.stage == 0:
            kind = "first" if self.staged() else "whole"
            self.pending = ev.send((kind, self.belief, self.action, remote, None), remote)
            self.stage = 1
        elif self.stage == 1 and self.first is not None and self.first.partial:
            job = ("rest", self.belief, self.action, remote, self.first.staged)
            self.pending = ev.send(job, remote)
            self.stage = 2

    def advance(self) -> None:
        """Ahead of the search: take a finished answer; a first share whose belief is not
        dominated *now* sends the rest (one dominated now is dominated when the search asks:
        the index only grows)."""
        if self.pending is not None and self.first is None and self.pending.done():
            answer = self._take()
            if answer.partial and not self.evaluator.dominated(answer.child):
                self.send()

    def _take(self) -> _Answer:
        """Wait for the job sent last; its answer is kept in ``first`` until the search asks."""
        assert self.pending is not None
        answer = self.pending.result()
        self.pending = None
        self.first = answer
        return answer

    def __call__(self) -> Any:
        ev = self.evaluator
        self.done = True
        if self.stage == 0:
            self.send()
        answer = self.first if self.first is not None else self._take()
        ev.simulations += answer.simulations
        if answer.partial:
            # the test runs now, against the index as the search has it now (module doc)
            if ev.dominated(answer.child):
                if self.pending is not None:  # the rest, sent ahead, is not needed
                    self.pending.cancel()
                self._release()
                return DOMINATED
            self.send()  # the rest, unless it was sent ahead
            self.first = None
            answer = self._take()
            ev.simulations += answer.simulations
        self._release()
        ev.last = (answer.child, answer.h)
        return answer.child

    def _release(self) -> None:
        self.first = None
        self.pending = None


class SuccessorEvaluator:
    """Computes the search's successor beliefs for one planning run (see the module doc).

    ``runner`` runs the jobs (a serial runner: here, each when the search asks for it);
    ``spec`` is what the workers build their task from (ignored by a serial runner, which uses
    ``task``); ``index`` is the search's dominance index (None: no staged pushes).
    :attr:`simulations` counts the simulations of the children the search asked for, the
    same for any runner; :attr:`sent` counts the jobs sent, among them those computed ahead
    that the search never asked for.
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
        self.ahead = runner.workers > 1
        here = _InProcess(task)
        # places and picks are computed here, pushes (the physics) on the runner
        self.here: Session[tuple[Any, ...], _Answer] = SerialRunner().session(_work, here)
        self.session = runner.session(_work, spec) if self.ahead else self.here
        self.simulations = 0
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
        """Send the children of ``edges`` (the next the search will evaluate, in order) to the
        workers while they have room; no-op with one worker."""
        if not self.ahead:
            return
        for child in list(self._sent):
            child.advance()
        room = AHEAD_PER_WORKER * self.runner.workers
        self._sent = deque(c for c in self._sent if not c.done and c.pending is not None)
        busy = sum(1 for c in self._sent if not c.pending.done())  # type: ignore[union-attr]
        for edge in edges:
            child = edge.make_child
            if not isinstance(child, _Child) or child.done or child.stage:
                continue
            if not isinstance(child.action, Push):
                continue  # places and picks cost less than a round trip: done here when asked
            if busy >= room:
                break
            child.send()
            busy += 1
            self._sent.append(child)
            self._ahead.append(child)
        while len(self._ahead) > KEPT_AHEAD:
            dropped = self._ahead.popleft()
            if not dropped.done:
                if dropped.pending is not None:
                    dropped.pending.cancel()
                dropped.stage, dropped.pending, dropped.first = 0, None, None

    # -- helpers ---------------------------------------------------------------------------------
    def send(self, job: tuple[Any, ...], remote: bool) -> Pending[_Answer]:
        self.sent += 1
        return (self.session if remote else self.here).submit(job)

    def dominated(self, partial: ParticleBelief) -> bool:
        assert self.index is not None
        return self.index.dominated(partial, 0.0)

    def close(self) -> None:
        for child in self._sent:
            if child.pending is not None:
                child.pending.cancel()
        if self.session is not self.here:
            self.session.close()
