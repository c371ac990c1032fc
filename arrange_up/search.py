"""Generic best-first search with deferred (lazy) successor evaluation.

This module knows nothing about geometry, physics or belief states: a *state* is any hashable,
immutable value, and an *action* is any value the caller wants back in the plan. It is modelled
on pyperplan's ``search`` package and predicators' ``run_astar``: plain functions, small
dataclasses, no framework.

Why deferred evaluation
-----------------------
In arrange-up a successor is a belief state predicted by a physics simulation of many particles,
which costs milliseconds, and most generated successors are never expanded. A successor is
therefore handed to the search as an :class:`Edge` ``(action, cost, make_child)`` whose
``make_child()`` computes the child (or returns ``None`` when there is no prediction / the
transition is invalid). With ``deferred=True`` (Fast Downward's *lazy search*) the edge itself is
queued and ``make_child`` runs only when the edge is popped; with ``deferred=False`` (*eager*) the
child is computed at generation and queued with its own heuristic value.

Design choices (the contracts the planner relies on)
----------------------------------------------------
* **Goal test at selection.** A node is goal-tested when it is popped for expansion, never at
  generation, so A* with an admissible heuristic returns an optimal plan. In deferred mode the
  pop first computes the child, then runs duplicate detection, dominance, the heuristic, and only
  then the goal test.
* **Duplicate detection with reopening.** The search keeps, for every state ever accepted, the
  cheapest ``g`` it was reached with. A newly reached copy is discarded unless it is strictly
  cheaper; a strictly cheaper copy replaces the old one (the old open entry becomes stale and is
  dropped when popped) and, if the state had already been expanded, the state is *reopened* and
  expanded again (``reopen=True``, the default, which keeps A* optimal even with an admissible
  but inconsistent heuristic; with a consistent heuristic A* never reopens). ``reopen=False`` is
  the usual weighted-A* shortcut: an expanded state is never expanded again.
* **Deferred priorities.** An edge ``parent --cost--> ?`` is queued with
  ``g = g(parent) + cost`` and the estimate ``h = max(h(parent) - cost, 0)``, i.e. priority
  ``g(parent) + cost + weight * max(h(parent) - cost, 0)``. The estimate is the smallest value a
  *consistent* heuristic allows the child to have, so it never overestimates the child's ``f``
  and deferred A* stays optimal with a consistent heuristic (queueing with the raw ``h(parent)``
  can pop a suboptimal goal first when costs differ). With unit costs and ``h(parent) >= 1`` it
  is the raw ``g + 1 + weight * h(parent)`` shifted by the constant ``weight``, so the order is
  the same.
* **Dominance pruning** (thesis, section 2.1.2). ``dominates(a, b)`` means "``a`` is at least as
  good as ``b``". Accepted states are kept in buckets by ``dominance_key`` and a newly reached
  state is compared only with the accepted states of its own bucket. By default
  (``dominance_ignores_g=False``) a state is pruned only if a dominating state was reached with
  ``g`` no larger than its own, which is safe for optimality whenever dominance means "can do
  everything the other can, at no greater cost". ``dominance_ignores_g=True`` is the thesis's
  rule (prune any state dominated by a visited one, whatever the costs): it prunes more, and
  plans stay valid, but optimality is lost. "Visited" means *accepted*: in eager mode that
  includes states still waiting in the open list, in deferred mode only states whose child was
  computed. Open entries that become dominated by a later state are not removed.
* **Infinite heuristic** values (``math.inf``) mark dead ends: the state is pruned and counted.
* **Honest statuses.** ``NODE_LIMIT`` is returned the moment a node would be expanded beyond
  ``max_nodes``, so ``EXHAUSTED`` (open list ran empty) is never caused by the node limit. It
  is not a proof that no plan exists: states with infinite heuristic, edges with no prediction
  and, when dominance is on, dominated states were not explored. The search never returns
  ``UNSOLVABLE``; that status is for callers that prove a problem unsolvable before searching.
* **Tie-breaking.** The open list is ordered by ``(f, h)`` (greedy: ``(h, g)``), then a
  tie-breaker, then insertion order. With ``tie_break_seed=None`` the tie-breaker is constant, so
  ties among equal ``(f, h)`` are FIFO. With an integer seed it is a draw from
  ``random.Random(seed)``: the run is reproducible, and different seeds explore equally good
  nodes in different orders and so may return different, equally good plans.
"""

from __future__ import annotations

import enum
import gc
import heapq
import itertools
import math
import random
import time
from collections import OrderedDict
from collections.abc import Callable, Hashable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, replace
from typing import Any, Generic, Protocol, TypeVar

__all__ = [
    "COLLECTION_THRESHOLD",
    "DEAD_END_CACHE",
    "DOMINATED",
    "PROGRESS_INTERVAL",
    "Edge",
    "SearchOptions",
    "SearchResult",
    "SearchStats",
    "SearchStatus",
    "astar",
    "best_first_search",
    "greedy_best_first",
    "uniform_cost",
    "weighted_astar",
]

S = TypeVar("S", bound=Hashable)
A = TypeVar("A")

#: Seconds between two calls of the ``progress`` callback (it is also called once at the end).
PROGRESS_INTERVAL = 0.2
#: Dead ends (states of infinite heuristic) whose value the search remembers, most recently
#: seen first. Accepted states are kept anyway (duplicate detection needs them); dead ends are
#: not, and caching every one kept each pruned state's belief alive for the whole search.
DEAD_END_CACHE = 4096
#: The garbage collector's youngest-generation threshold while a search runs (CPython's default
#: is 700; a larger one set before is kept). Most of what a search allocates lives until it
#: ends (accepted states, queued edges, the transitions' caches) and holds no cycles, so the
#: collector's frequent passes, and the full ones they lead to, mostly walk live objects.
COLLECTION_THRESHOLD = 20_000


@contextmanager
def _fewer_collections() -> Iterator[None]:
    """Run the body with the youngest generation's threshold at least
    :data:`COLLECTION_THRESHOLD`, then restore the thresholds as they were."""
    before = gc.get_threshold()
    gc.set_threshold(max(before[0], COLLECTION_THRESHOLD), *before[1:])
    try:
        yield
    finally:
        gc.set_threshold(*before)


class SearchStatus(enum.StrEnum):
    """How a search ended.

    A string enum: a member equals (and formats, and serialises as) its value, which is how
    statuses are written in plan files and ``--json`` output (``"node-limit"``, ...).
    """

    #: A goal state was popped; the result carries the plan.
    SOLVED = "solved"
    #: ``max_nodes`` expansions were done and another node was about to be expanded.
    NODE_LIMIT = "node-limit"
    #: The wall-clock ``timeout`` passed.
    TIMEOUT = "timeout"
    #: The open list ran empty: no plan among the candidates the successors offered and the
    #: pruning kept (not a proof that none exists).
    EXHAUSTED = "exhausted"
    #: Proven before any search: no plan exists (e.g. a goal part cannot fit on the table).
    #: Plan files written before ``EXHAUSTED`` existed use it for exhausted searches too.
    UNSOLVABLE = "unsolvable"
    #: ``should_stop()`` returned True.
    CANCELLED = "cancelled"


class DominanceIndex(Protocol):
    """A custom store of accepted states for dominance pruning.

    For state types where pairwise ``dominates`` calls over a bucket are too slow (thousands of
    accepted states), a caller can index states itself, e.g. vectorised with numpy. The search
    asks :meth:`dominated` of every newly reached state that is not a duplicate, and calls
    :meth:`add` for every accepted one.
    """

    def dominated(self, state: Any, g: float) -> bool:
        """True if an already added state dominates ``state`` (reached with cost ``g``)."""
        ...

    def add(self, state: Any, g: float) -> None:
        """Record an accepted state."""
        ...


class _Dominated:
    """The type of :data:`DOMINATED` (one instance; it survives no pickling, nor needs to)."""

    def __repr__(self) -> str:
        return "DOMINATED"


#: What ``make_child`` returns when it has shown, before computing the whole child, that the
#: search's dominance test would prune it (a staged evaluation; see
#: :mod:`arrange_up.planning.successors`). The search counts it as ``pruned_dominated``.
DOMINATED: Any = _Dominated()


def _constant(value: Any) -> Callable[[], Any]:
    # A named factory rather than an inline lambda so each Edge gets its own closure over `value`.
    return lambda: value


@dataclass(frozen=True)
class Edge(Generic[S, A]):
    """One outgoing transition of a state, with its child computed on demand.

    Attributes
    ----------
    action
        What the plan records for this transition.
    cost
        Finite, non-negative cost of the transition.
    make_child
        Computes the child state, or returns ``None`` when the transition has no prediction or is
        invalid, or :data:`DOMINATED` when it has shown that the child would be pruned as
        dominated (it may consult the search's ``dominance_index`` to do so). Called at most
        once per edge by the search (at generation in eager mode, when the edge is popped in
        deferred mode, or never if the edge is left in the open list).
    """

    action: A
    cost: float
    make_child: Callable[[], S | None]

    @classmethod
    def known(cls, action: A, cost: float, child: S | None) -> Edge[S, A]:
        """An edge whose child is already computed (``make_child`` just returns it)."""
        return cls(action, cost, _constant(child))


@dataclass
class SearchStats:
    """Exact counters of one search.

    Attributes
    ----------
    expanded
        Nodes whose successors were generated (``successors`` calls); never exceeds
        ``max_nodes``. A reopened state counts once per expansion.
    generated
        Edges yielded by ``successors`` over all expansions.
    evaluated
        ``make_child`` calls. Equal to ``generated`` in eager mode (unless the search stops in
        the middle of an expansion); in deferred mode the edges still queued at the end are
        never evaluated.
    pruned_dominated
        Children discarded because an accepted state of the same dominance key dominates them
        (including those ``make_child`` found dominated, :data:`DOMINATED`).
    pruned_infinite
        States discarded because the heuristic returned ``math.inf`` (including the start).
    pruned_duplicate
        Discarded duplicates: a child whose state was already reached with ``g`` no larger than
        its own (or already expanded, with ``reopen=False``), plus open entries found stale when
        popped because a cheaper path to their state (deferred: to their parent's state) was
        found while they waited. Stale deferred edges are dropped without calling
        ``make_child``.
    no_prediction
        ``make_child`` calls that returned ``None``.
    reopened
        Expansions of a state that had already been expanded with a larger ``g``.
    best_h
        Smallest finite heuristic value of an accepted state (``inf`` if none).
    elapsed
        Wall-clock seconds since the search started (as measured by its clock); final at the end.
    """

    expanded: int = 0
    generated: int = 0
    evaluated: int = 0
    pruned_dominated: int = 0
    pruned_infinite: int = 0
    pruned_duplicate: int = 0
    no_prediction: int = 0
    reopened: int = 0
    best_h: float = math.inf
    elapsed: float = 0.0


@dataclass(frozen=True)
class SearchResult(Generic[S, A]):
    """Outcome of a search.

    ``plan``, ``states`` and ``cost`` are set if and only if ``status`` is ``SOLVED``; then
    ``states`` runs from the start to the goal state, ``len(states) == len(plan) + 1``, and
    ``cost`` is the sum of the plan's edge costs. ``best`` is an accepted state of the smallest
    heuristic value (the first reached; ``stats.best_h`` is its value), None if none was
    accepted: for an unsolved search, the state it came closest to the goal with.
    """

    status: SearchStatus
    plan: tuple[A, ...] | None
    states: tuple[S, ...] | None
    cost: float | None
    stats: SearchStats
    best: S | None = None

    def __post_init__(self) -> None:
        solved = self.status is SearchStatus.SOLVED
        if any((part is not None) != solved for part in (self.plan, self.states, self.cost)):
            raise ValueError("plan, states and cost must be set iff the status is SOLVED")
        if self.plan is not None and self.states is not None:
            if len(self.states) != len(self.plan) + 1:
                raise ValueError("states must have exactly one more element than plan")

    def solved(self) -> bool:
        """True iff a plan was found."""
        return self.status is SearchStatus.SOLVED


def _blind(state: Any) -> float:
    """The blind heuristic, 0 everywhere."""
    return 0.0


@dataclass(slots=True, eq=False)
class _Node:
    """A search node: a state reached by a particular path (the parent chain)."""

    state: Any
    g: float
    h: float
    parent: _Node | None
    action: Any


class _Search:
    """The state of one best-first search; see :func:`best_first_search` for the contract."""

    def __init__(
        self,
        successors: Callable[[Any], Iterable[Edge[Any, Any]]],
        is_goal: Callable[[Any], bool],
        heuristic: Callable[[Any], float],
        options: SearchOptions[Any, Any],
    ) -> None:
        self.successors = successors
        self.is_goal = is_goal
        self.heuristic = heuristic
        self.weight = options.weight
        self.greedy = options.greedy
        self.deferred = options.deferred
        self.dominates = options.dominates
        self.dominance_key = options.dominance_key
        self.dominance_ignores_g = options.dominance_ignores_g
        self.dominance_index = options.dominance_index
        self.reopen = options.reopen
        self.max_nodes = options.max_nodes
        self.timeout = options.timeout
        self.progress = options.progress
        self.should_stop = options.should_stop
        self.clock = options.clock
        self.prefetch = options.prefetch
        self.prefetch_depth = options.prefetch_depth
        seed = options.tie_break_seed
        self.rng = random.Random(seed) if seed is not None else None

        self.stats = SearchStats()
        self.best: Any = None
        # Cheapest g each accepted state was reached with (the duplicate-detection table).
        self.g_best: dict[Any, float] = {}
        # States expanded at least once (value: g of the last expansion).
        self.closed: dict[Any, float] = {}
        # The heuristic may be as expensive as a successor, so each accepted state is evaluated
        # once, and a dead end once while it stays among the DEAD_END_CACHE most recent.
        self.h_cache: dict[Any, float] = {}
        self.dead_ends: OrderedDict[Any, None] = OrderedDict()
        # Dominance buckets: key -> {accepted state: its best g}. A dict per bucket so that a
        # state reached again more cheaply updates its g in place.
        self.buckets: dict[Hashable, dict[Any, float]] = {}
        # Heap entries: (primary, secondary, tie-breaker, insertion number, payload). The
        # insertion number is unique, so payloads (nodes, edges) are never compared.
        self.open: list[tuple[float, float, float, int, Any]] = []
        self.counter = itertools.count()
        self.t0 = 0.0
        self.last_progress = 0.0
        self.deadline: float | None = None

    # -- open list -------------------------------------------------------------------------------
    def push(self, payload: Any, g: float, h: float) -> None:
        if self.greedy:
            primary, secondary = h, g
        else:
            primary, secondary = g + self.weight * h, h
        tie = self.rng.random() if self.rng is not None else 0.0
        heapq.heappush(self.open, (primary, secondary, tie, next(self.counter), payload))

    # -- acceptance pipeline: duplicates, dominance, heuristic -----------------------------------
    def accept(self, state: Any, g: float) -> float | None:
        """Return the heuristic value of ``state`` reached with ``g``, or None if it is pruned.

        Every rejection is counted in exactly one ``pruned_*`` counter. On acceptance the state
        is recorded in the duplicate table and in its dominance bucket.
        """
        stats = self.stats
        known = self.g_best.get(state)
        if known is not None and (known <= g or (not self.reopen and state in self.closed)):
            stats.pruned_duplicate += 1
            return None
        bucket: dict[Any, float] | None = None
        if self.dominates is not None:
            key = self.dominance_key(state) if self.dominance_key is not None else None
            bucket = self.buckets.setdefault(key, {})
            if self._dominated(state, g, bucket):
                stats.pruned_dominated += 1
                return None
        elif self.dominance_index is not None and self.dominance_index.dominated(state, g):
            stats.pruned_dominated += 1
            return None
        h = self.h_cache.get(state)
        if h is None:
            if state in self.dead_ends:
                self.dead_ends.move_to_end(state)
                stats.pruned_infinite += 1
                return None
            h = float(self.heuristic(state))
            if math.isnan(h):
                raise ValueError(f"heuristic returned NaN for state {state!r}")
            if h == math.inf:
                self.dead_ends[state] = None
                if len(self.dead_ends) > DEAD_END_CACHE:
                    self.dead_ends.popitem(last=False)
                stats.pruned_infinite += 1
                return None
            self.h_cache[state] = h
        if h < stats.best_h:
            stats.best_h = h
            self.best = state
        self.g_best[state] = g
        if bucket is not None:
            bucket[state] = g
        elif self.dominance_index is not None:
            self.dominance_index.add(state, g)
        return h

    def _dominated(self, state: Any, g: float, bucket: dict[Any, float]) -> bool:
        assert self.dominates is not None
        for other, g_other in bucket.items():
            if other == state:
                # The same state reached again more cheaply (duplicate detection let it
                # through): that is a reopening, not dominance.
                continue
            if not self.dominance_ignores_g and g_other > g:
                continue
            if self.dominates(other, state):
                return True
        return False

    def evaluate(self, parent: _Node, edge: Edge[Any, Any]) -> _Node | None:
        """Compute the child of ``edge`` and run it through :meth:`accept`."""
        self.stats.evaluated += 1
        child = edge.make_child()
        if child is None:
            self.stats.no_prediction += 1
            return None
        if child is DOMINATED:
            self.stats.pruned_dominated += 1
            return None
        g = parent.g + edge.cost
        h = self.accept(child, g)
        if h is None:
            return None
        return _Node(child, g, h, parent, edge.action)

    def upcoming(self) -> list[Edge[Any, Any]]:
        """The edges of the next ``prefetch_depth`` open entries, in the order they will be
        popped unless an expansion queues better ones (stale entries left out). The k-th
        smallest entry of a heap lies in its first k levels, so those are all it reads."""
        depth = self.prefetch_depth
        entries = heapq.nsmallest(depth, self.open[: 2**depth - 1])
        edges = []
        for *_, payload in entries:
            if isinstance(payload, tuple):
                parent, edge = payload
                if parent.g <= self.g_best[parent.state]:
                    edges.append(edge)
        return edges

    # -- stopping ----------------------------------------------------------------------------------
    def interrupted(self) -> SearchStatus | None:
        """Check cancellation and the deadline, and report progress when it is due."""
        if self.should_stop is not None and self.should_stop():
            return SearchStatus.CANCELLED
        now = self.clock()
        self.stats.elapsed = now - self.t0
        if self.progress is not None and now - self.last_progress >= PROGRESS_INTERVAL:
            self.last_progress = now
            self.progress(replace(self.stats))
        if self.deadline is not None and now >= self.deadline:
            return SearchStatus.TIMEOUT
        return None

    # -- main loop -------------------------------------------------------------------------------
    def expand(self, node: _Node) -> SearchStatus | None:
        stats = self.stats
        stats.expanded += 1
        if node.state in self.closed:
            stats.reopened += 1
        self.closed[node.state] = node.g
        edges: Iterable[Edge[Any, Any]] = self.successors(node.state)
        if self.prefetch is not None and not self.deferred:
            edges = list(edges)  # eager: every one is evaluated next, in this order
            self.prefetch(edges)
        for edge in edges:
            cost = edge.cost
            if not 0.0 <= cost < math.inf:
                raise ValueError(f"edge cost must be finite and non-negative, got {cost!r}")
            stats.generated += 1
            if self.deferred:
                self.push((node, edge), node.g + cost, max(node.h - cost, 0.0))
                continue
            # Eager: each child may be a long simulation, so honour the deadline and
            # cancellation between children, not only between expansions.
            status = self.interrupted()
            if status is not None:
                return status
            child = self.evaluate(node, edge)
            if child is not None:
                self.push(child, child.g, child.h)
        return None

    def run(self, start: Any) -> SearchResult[Any, Any]:
        with _fewer_collections():
            return self._run(start)

    def _run(self, start: Any) -> SearchResult[Any, Any]:
        self.t0 = self.last_progress = self.clock()
        if self.timeout is not None:
            self.deadline = self.t0 + self.timeout
        h0 = self.accept(start, 0.0)
        if h0 is not None:
            self.push(_Node(start, 0.0, h0, None, None), 0.0, h0)
        stats = self.stats
        while self.open:
            status = self.interrupted()
            if status is not None:
                return self.finish(status)
            payload = heapq.heappop(self.open)[-1]
            if isinstance(payload, _Node):
                node = payload
                if node.g > self.g_best[node.state]:
                    stats.pruned_duplicate += 1  # superseded by a cheaper copy
                    continue
            else:
                parent, edge = payload
                if parent.g > self.g_best[parent.state]:
                    # The parent was reached more cheaply and re-expanded since this edge was
                    # queued; that expansion queued the same edge with a smaller g, so skip the
                    # simulation.
                    stats.pruned_duplicate += 1
                    continue
                if self.prefetch is not None:
                    self.prefetch([edge, *self.upcoming()])
                evaluated = self.evaluate(parent, edge)
                if evaluated is None:
                    continue
                node = evaluated
            if self.is_goal(node.state):
                return self.finish(SearchStatus.SOLVED, node)
            if self.max_nodes is not None and stats.expanded >= self.max_nodes:
                return self.finish(SearchStatus.NODE_LIMIT)
            status = self.expand(node)
            if status is not None:
                return self.finish(status)
        return self.finish(SearchStatus.EXHAUSTED)

    def finish(self, status: SearchStatus, goal: _Node | None = None) -> SearchResult[Any, Any]:
        self.stats.elapsed = self.clock() - self.t0
        if self.progress is not None:
            self.progress(replace(self.stats))
        if goal is None:
            return SearchResult(status, None, None, None, self.stats, self.best)
        actions: list[Any] = []
        states: list[Any] = []
        node: _Node | None = goal
        while node is not None:
            states.append(node.state)
            if node.parent is not None:
                actions.append(node.action)
            node = node.parent
        return SearchResult(
            status, tuple(reversed(actions)), tuple(reversed(states)), goal.g, self.stats, self.best
        )


@dataclass(frozen=True)
class SearchOptions(Generic[S, A]):
    """How :func:`best_first_search` searches, as one value; every field has its default.
    Bad values raise ``ValueError`` when it is made.

    Fields:

    weight
        Open list ordered by ``f = g + weight * h``: 1 is A*, > 1 weighted A* (plans cost at
        most ``weight`` times the optimum for an admissible heuristic), 0 uniform cost. Ignored
        when ``greedy``.
    greedy
        Order by ``h`` alone, ties broken by smaller ``g``.
    deferred
        Lazy evaluation: queue edges with ``g(parent) + cost`` and the estimate
        ``max(h(parent) - cost, 0)`` and call ``make_child`` only when the edge is popped.
        Eager (default): compute each child at generation and queue it with its own ``h``.
        Both are optimal for ``weight=1`` with a consistent heuristic; eager A* also with an
        admissible one (thanks to reopening).
    dominates
        ``dominates(a, b)`` is True when ``a`` is at least as good as ``b``; a newly reached
        ``b`` is pruned if an accepted ``a`` of the same ``dominance_key`` dominates it (see
        ``dominance_ignores_g``). None disables dominance pruning.
    dominance_key
        Only states with equal keys are compared (e.g. the same set of objects on the table),
        so each check costs the size of one bucket. None puts every state in one bucket.
        Requires ``dominates``.
    dominance_ignores_g
        False (default): prune ``b`` only if the dominating ``a`` was reached with
        ``g(a) <= g(b)``, which preserves optimality. True: the thesis's rule, prune regardless
        of cost (more pruning, plans still valid but possibly longer).
    dominance_index
        Alternative to ``dominates``/``dominance_key``: a :class:`DominanceIndex` that stores
        accepted states and answers dominance queries itself (its own rule, g included).
    reopen
        Re-expand an already expanded state when it is reached strictly more cheaply (default).
        False never expands a state twice (cheaper for weighted/greedy search).
    max_nodes
        Maximum number of expansions; when one more would be needed the search returns
        ``NODE_LIMIT`` with ``stats.expanded == max_nodes``. None: unlimited.
    timeout
        Wall-clock budget in seconds (measured with ``clock``), checked before every pop and, in
        eager mode, before every child evaluation. None: unlimited.
    tie_break_seed
        None: ties among equal ``(f, h)`` are broken first-in first-out. An integer: broken by a
        ``random.Random(tie_break_seed)`` draw, reproducibly; different seeds can give
        different, equally good plans.
    progress
        Called with a snapshot (copy) of the statistics about every ``PROGRESS_INTERVAL``
        seconds and once at the end.
    should_stop
        Polled as often as the deadline; when it returns True the search ends with
        ``CANCELLED``.
    clock
        Monotonic clock in seconds, injectable for tests. Default: ``time.monotonic``.
    prefetch
        Told which edges the search will evaluate next, so that their children can be
        computed ahead (in parallel): in deferred mode, before each popped edge is evaluated,
        that edge and those of the next ``prefetch_depth`` open entries; in eager mode, all of
        an expansion's edges before the first is evaluated. A hint only: the search evaluates
        edges in the same order, calling ``make_child`` as it would without it.
    prefetch_depth
        Open entries looked at for ``prefetch`` in deferred mode (at most 10).
    """

    weight: float = 1.0
    greedy: bool = False
    deferred: bool = False
    dominates: Callable[[S, S], bool] | None = None
    dominance_key: Callable[[S], Hashable] | None = None
    dominance_ignores_g: bool = False
    dominance_index: DominanceIndex | None = None
    reopen: bool = True
    max_nodes: int | None = 5000
    timeout: float | None = None
    tie_break_seed: int | None = None
    progress: Callable[[SearchStats], None] | None = None
    should_stop: Callable[[], bool] | None = None
    clock: Callable[[], float] = time.monotonic
    prefetch: Callable[[list[Edge[S, A]]], None] | None = None
    prefetch_depth: int = 4

    def __post_init__(self) -> None:
        weight, max_nodes, timeout = self.weight, self.max_nodes, self.timeout
        if not weight >= 0.0 or weight == math.inf:
            raise ValueError(f"weight must be finite and non-negative, got {weight!r}")
        if max_nodes is not None and max_nodes < 0:
            raise ValueError(f"max_nodes must be non-negative or None, got {max_nodes!r}")
        if timeout is not None and not timeout >= 0.0:
            raise ValueError(f"timeout must be non-negative or None, got {timeout!r}")
        if self.dominance_key is not None and self.dominates is None:
            raise ValueError("dominance_key is only meaningful together with dominates")
        if self.dominance_index is not None and self.dominates is not None:
            raise ValueError("give either dominates or dominance_index, not both")
        if not 0 <= self.prefetch_depth <= 10:
            raise ValueError(
                f"prefetch_depth must be between 0 and 10, got {self.prefetch_depth!r}"
            )
        object.__setattr__(self, "weight", float(weight))


def best_first_search(
    start: S,
    successors: Callable[[S], Iterable[Edge[S, A]]],
    is_goal: Callable[[S], bool],
    heuristic: Callable[[S], float] = _blind,
    options: SearchOptions[S, A] | None = None,
    **overrides: Any,
) -> SearchResult[S, A]:
    """Best-first search from ``start`` to a state satisfying ``is_goal``, as ``options``
    say (None: the defaults of :class:`SearchOptions`) with ``overrides`` of its fields by name
    (``best_first_search(s, succ, goal, h, max_nodes=50)``; an unknown name raises
    ``TypeError``).

    Parameters
    ----------
    start
        The initial state. States must be hashable and immutable; equal states are duplicates.
    successors
        ``successors(s)`` yields the outgoing :class:`Edge` objects of ``s``. Called once per
        expansion. Edge costs must be finite and non-negative (``ValueError`` otherwise).
    is_goal
        Goal test, applied when a node is selected for expansion (never at generation).
    heuristic
        Estimate of the remaining cost; ``math.inf`` marks a dead end (the state is pruned).
        Must be a function of the state: values are cached, finite ones for as long as the
        search runs, dead ends in a cache of the :data:`DEAD_END_CACHE` most recently seen
        (a dead end met again after leaving it is evaluated again). Default: blind (0).

    Returns
    -------
    SearchResult
        ``SOLVED`` with the plan, the states from start to goal and the cost; otherwise
        ``NODE_LIMIT``, ``TIMEOUT``, ``CANCELLED`` or ``EXHAUSTED`` (open list ran empty: no
        plan among the states explored, which leave out states with infinite heuristic, edges
        without prediction and dominated states; not a proof). The statistics are exact; see
        :class:`SearchStats`.

    Raises
    ------
    ValueError
        For an invalid parameter, a negative, infinite or NaN edge cost, or a NaN heuristic.
    """
    chosen: SearchOptions[S, A] = replace(options or SearchOptions(), **overrides)
    return _Search(successors, is_goal, heuristic, chosen).run(start)


def astar(
    start: S,
    successors: Callable[[S], Iterable[Edge[S, A]]],
    is_goal: Callable[[S], bool],
    heuristic: Callable[[S], float],
    **options: Any,
) -> SearchResult[S, A]:
    """A* (``weight=1``); ``options`` are the keyword arguments of :func:`best_first_search`."""
    return best_first_search(start, successors, is_goal, heuristic, weight=1.0, **options)


def weighted_astar(
    start: S,
    successors: Callable[[S], Iterable[Edge[S, A]]],
    is_goal: Callable[[S], bool],
    heuristic: Callable[[S], float],
    weight: float,
    **options: Any,
) -> SearchResult[S, A]:
    """Weighted A*, ``f = g + weight * h``; see :func:`best_first_search`."""
    return best_first_search(start, successors, is_goal, heuristic, weight=weight, **options)


def greedy_best_first(
    start: S,
    successors: Callable[[S], Iterable[Edge[S, A]]],
    is_goal: Callable[[S], bool],
    heuristic: Callable[[S], float],
    **options: Any,
) -> SearchResult[S, A]:
    """Greedy best-first search (order by ``h``, ties by ``g``); see :func:`best_first_search`."""
    return best_first_search(start, successors, is_goal, heuristic, greedy=True, **options)


def uniform_cost(
    start: S,
    successors: Callable[[S], Iterable[Edge[S, A]]],
    is_goal: Callable[[S], bool],
    **options: Any,
) -> SearchResult[S, A]:
    """Uniform-cost (Dijkstra) search: blind heuristic; see :func:`best_first_search`."""
    return best_first_search(start, successors, is_goal, _blind, **options)
