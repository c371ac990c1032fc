"""Tests of the generic best-first search on toy problems with no geometry at all."""

from __future__ import annotations

import heapq
import math
import random
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import pytest

from arrange_up.search import (
    Edge,
    SearchOptions,
    SearchResult,
    SearchStats,
    SearchStatus,
    astar,
    best_first_search,
    greedy_best_first,
    uniform_cost,
    weighted_astar,
)

# -- a small grid world ----------------------------------------------------------------------------

Pos = tuple[int, int]
MOVES: dict[str, Pos] = {"U": (0, -1), "D": (0, 1), "L": (-1, 0), "R": (1, 0)}


@dataclass
class Grid:
    """A grid with walls; entering cell ``p`` costs ``costs.get(p, 1)``.

    ``make_child_calls`` counts the successor computations the search asked for, and ``expanded``
    records the states whose successors were asked for, in order.
    """

    width: int
    height: int
    walls: frozenset[Pos] = frozenset()
    costs: dict[Pos, float] = field(default_factory=dict)
    make_child_calls: int = 0
    expanded: list[Pos] = field(default_factory=list)

    def free(self, p: Pos) -> bool:
        return 0 <= p[0] < self.width and 0 <= p[1] < self.height and p not in self.walls

    def step(self, p: Pos, action: str) -> Pos | None:
        dx, dy = MOVES[action]
        q = (p[0] + dx, p[1] + dy)
        return q if self.free(q) else None

    def _child(self, p: Pos, action: str) -> Callable[[], Pos | None]:
        def make_child() -> Pos | None:
            self.make_child_calls += 1
            return self.step(p, action)

        return make_child

    def successors(self, p: Pos) -> list[Edge[Pos, str]]:
        self.expanded.append(p)
        edges = []
        for action, (dx, dy) in MOVES.items():
            q = (p[0] + dx, p[1] + dy)
            if self.free(q):
                edges.append(Edge(action, self.costs.get(q, 1.0), self._child(p, action)))
        return edges

    def neighbours(self, p: Pos) -> list[tuple[Pos, float]]:
        return [(q, self.costs.get(q, 1.0)) for a in MOVES if (q := self.step(p, a)) is not None]


def manhattan(goal: Pos) -> Callable[[Pos], float]:
    # Every cell costs at least 1 to enter, so the Manhattan distance is consistent.
    return lambda p: float(abs(p[0] - goal[0]) + abs(p[1] - goal[1]))


def dijkstra(grid: Grid, start: Pos, goal: Pos) -> float | None:
    """Brute-force reference: the optimal cost, or None when the goal is unreachable."""
    dist = {start: 0.0}
    queue = [(0.0, start)]
    while queue:
        d, p = heapq.heappop(queue)
        if p == goal:
            return d
        if d > dist[p]:
            continue
        for q, c in grid.neighbours(p):
            if d + c < dist.get(q, math.inf):
                dist[q] = d + c
                heapq.heappush(queue, (d + c, q))
    return None


def random_grid(rng: random.Random, size: int = 8, wall_p: float = 0.25) -> tuple[Grid, Pos, Pos]:
    cells = [(x, y) for x in range(size) for y in range(size)]
    start, goal = rng.sample(cells, 2)
    walls = frozenset(c for c in cells if c not in (start, goal) and rng.random() < wall_p)
    costs = {c: float(rng.choice((1, 1, 2, 3))) for c in cells}
    return Grid(size, size, walls, costs), start, goal


def assert_valid_plan(grid: Grid, start: Pos, goal: Pos, result: SearchResult[Pos, str]) -> None:
    """Replay the plan action by action and check states, goal and cost."""
    assert result.solved()
    assert result.plan is not None and result.states is not None and result.cost is not None
    p, cost, states = start, 0.0, [start]
    for action in result.plan:
        q = grid.step(p, action)
        assert q is not None, f"invalid action {action} at {p}"
        cost += grid.costs.get(q, 1.0)
        p = q
        states.append(p)
    assert p == goal
    assert tuple(states) == result.states
    assert cost == pytest.approx(result.cost)


def solve_grid(grid: Grid, start: Pos, goal: Pos, **options) -> SearchResult[Pos, str]:
    options.setdefault("heuristic", manhattan(goal))
    return best_first_search(start, grid.successors, lambda p: p == goal, **options)


# -- a few other toy domains -----------------------------------------------------------------------


def line_successors(n: int) -> list[Edge[int, str]]:
    """The unbounded integer line, unit steps both ways."""
    return [Edge.known("-", 1.0, n - 1), Edge.known("+", 1.0, n + 1)]


class FakeClock:
    """A clock that advances by ``tick`` seconds each time it is read."""

    def __init__(self, tick: float) -> None:
        self.now = 0.0
        self.tick = tick

    def __call__(self) -> float:
        self.now += self.tick
        return self.now


# -- optimality ------------------------------------------------------------------------------------


@pytest.mark.parametrize("deferred", [False, True])
def test_astar_is_optimal_on_random_grids(deferred: bool) -> None:
    rng = random.Random(1234)
    solved = unsolvable = 0
    for _ in range(60):
        grid, start, goal = random_grid(rng, wall_p=0.35)
        reference = dijkstra(grid, start, goal)
        result = solve_grid(grid, start, goal, deferred=deferred, max_nodes=None)
        if reference is None:
            assert result.status is SearchStatus.EXHAUSTED
            assert result.plan is None and result.cost is None
            unsolvable += 1
        else:
            assert result.cost == pytest.approx(reference)
            assert_valid_plan(grid, start, goal, result)
            solved += 1
        assert result.stats.evaluated == grid.make_child_calls
        if not deferred:
            # Consistent heuristic: open copies superseded by cheaper ones are dropped, never
            # expanded, so no state is expanded twice.
            assert len(grid.expanded) == len(set(grid.expanded)) == result.stats.expanded
    assert solved > 20 and unsolvable > 0  # both branches were exercised


def test_eager_and_deferred_agree_and_deferred_evaluates_less() -> None:
    rng = random.Random(7)
    fewer = 0
    for _ in range(30):
        grid_e, start, goal = random_grid(rng, wall_p=0.15)
        grid_d = Grid(grid_e.width, grid_e.height, grid_e.walls, grid_e.costs)
        eager = solve_grid(grid_e, start, goal, max_nodes=None)
        lazy = solve_grid(grid_d, start, goal, deferred=True, max_nodes=None)
        assert eager.status is lazy.status
        assert eager.cost == lazy.cost
        # Eager evaluates every generated edge; deferred only the popped ones.
        assert eager.stats.evaluated == eager.stats.generated
        assert lazy.stats.evaluated <= lazy.stats.generated
        fewer += lazy.stats.evaluated < eager.stats.evaluated
    assert fewer > 15


def test_uniform_cost_matches_dijkstra() -> None:
    rng = random.Random(99)
    for _ in range(20):
        grid, start, goal = random_grid(rng)
        result = uniform_cost(start, grid.successors, lambda p, g=goal: p == g, max_nodes=None)
        reference = dijkstra(grid, start, goal)
        assert result.cost == (None if reference is None else pytest.approx(reference))


def test_consistent_heuristic_expands_each_state_once() -> None:
    grid = Grid(7, 7, walls=frozenset({(3, y) for y in range(1, 7)}))
    result = solve_grid(grid, (0, 6), (6, 6))
    assert result.solved()
    assert len(grid.expanded) == len(set(grid.expanded)) == result.stats.expanded
    assert result.stats.pruned_duplicate > 0
    assert result.stats.reopened == 0


def _inconsistent_graph() -> tuple[dict, dict]:
    # S-A-C costs 4, S-B-C costs 3; h(B) = 4 is admissible but inconsistent (h(C) = 0), so A*
    # first expands C via A and must reopen it when the cheaper path through B shows up.
    graph = {
        "S": [("A", 1.0), ("B", 2.0)],
        "A": [("C", 3.0)],
        "B": [("C", 1.0)],
        "C": [("G", 3.0)],
        "G": [],
    }
    h = {"S": 0.0, "A": 0.0, "B": 4.0, "C": 0.0, "G": 0.0}
    return graph, h


def test_reopening_keeps_astar_optimal_with_inconsistent_heuristic() -> None:
    graph, h = _inconsistent_graph()

    def successors(s: str) -> list[Edge[str, str]]:
        return [Edge.known(f"{s}->{t}", c, t) for t, c in graph[s]]

    result = astar("S", successors, lambda s: s == "G", h.__getitem__)
    assert result.cost == 6.0
    assert result.states == ("S", "B", "C", "G")
    assert result.stats.reopened == 1
    no_reopen = astar("S", successors, lambda s: s == "G", h.__getitem__, reopen=False)
    assert no_reopen.cost == 7.0
    assert no_reopen.stats.reopened == 0


def graph_successors(
    graph: dict[str, list[tuple[str, float]]], calls: list[tuple[str, str]] | None = None
) -> Callable[[str], list[Edge[str, str]]]:
    """Successors of an explicit graph; ``calls`` records every ``make_child`` (parent, child)."""

    def successors(s: str) -> list[Edge[str, str]]:
        def child(t: str) -> Callable[[], str]:
            def make_child() -> str:
                if calls is not None:
                    calls.append((s, t))
                return t

            return make_child

        return [Edge(f"{s}->{t}", c, child(t)) for t, c in graph[s]]

    return successors


@pytest.mark.parametrize("deferred", [False, True])
def test_optimal_with_consistent_heuristic_and_unequal_costs(deferred: bool) -> None:
    # Consistent h. Queueing the edge Q->G with the raw h(Q) = 0 (priority 11.5) ahead of P->G
    # with h(P) = 10 (priority 21) would return the 11.5 plan; the deferred estimate
    # max(h(parent) - cost, 0) gives P->G priority 11 and keeps deferred A* optimal.
    graph = {"S": [("P", 1.0), ("Q", 1.0)], "P": [("G", 10.0)], "Q": [("G", 10.5)], "G": []}
    h = {"S": 1.0, "P": 10.0, "Q": 0.0, "G": 0.0}
    result = astar(
        "S", graph_successors(graph), lambda s: s == "G", h.__getitem__, deferred=deferred
    )
    assert result.cost == 11.0 and result.states == ("S", "P", "G")


def test_deferred_skips_edges_of_superseded_parents() -> None:
    # The inconsistent h(B) makes C (and the chain after it) be expanded first via the costlier
    # path S-A-C and then reopened via S-B-C. The edge F->H queued by the costlier expansion of
    # F is popped after F was reached more cheaply: it is dropped without a simulation.
    graph = {
        "S": [("A", 1.0), ("B", 2.0)],
        "A": [("C", 3.0)],
        "B": [("C", 1.0)],
        "C": [("E", 1.0)],
        "E": [("F", 1.0)],
        "F": [("G", 1.0)],
        "G": [("H", 1.0)],
        "H": [],
    }
    h = {"S": 0.0, "B": 4.0}
    calls: list[tuple[str, str]] = []
    result = astar(
        "S",
        graph_successors(graph, calls),
        lambda s: s == "H",
        lambda s: h.get(s, 0.0),
        deferred=True,
    )
    assert result.cost == 7.0 and result.states == ("S", "B", "C", "E", "F", "G", "H")
    assert result.stats.reopened > 0 and result.stats.pruned_duplicate > 0
    assert calls.count(("F", "G")) == 1  # only from the cheaper expansion of F
    assert result.stats.evaluated == len(calls)


# -- weighted and greedy ---------------------------------------------------------------------------


@pytest.mark.parametrize("weight", [1.5, 3.0])
@pytest.mark.parametrize("deferred", [False, True])
def test_weighted_astar_returns_valid_bounded_plans(weight: float, deferred: bool) -> None:
    rng = random.Random(5)
    for _ in range(25):
        grid, start, goal = random_grid(rng, wall_p=0.2)
        reference = dijkstra(grid, start, goal)
        result = weighted_astar(
            start,
            grid.successors,
            lambda p, g=goal: p == g,
            manhattan(goal),
            weight,
            deferred=deferred,
            max_nodes=None,
        )
        if reference is None:
            assert result.status is SearchStatus.EXHAUSTED
            continue
        assert_valid_plan(grid, start, goal, result)
        assert result.cost <= weight * reference + 1e-9


def test_greedy_expands_no_more_than_astar_on_easy_instance() -> None:
    walls = frozenset({(5, y) for y in range(2, 9)})
    start, goal = (0, 5), (9, 5)
    grid_g, grid_a = Grid(10, 10, walls), Grid(10, 10, walls)
    greedy = greedy_best_first(start, grid_g.successors, lambda p: p == goal, manhattan(goal))
    optimal = astar(start, grid_a.successors, lambda p: p == goal, manhattan(goal))
    assert_valid_plan(grid_g, start, goal, greedy)
    assert greedy.stats.expanded <= optimal.stats.expanded
    assert greedy.cost >= optimal.cost


# -- limits and statuses ---------------------------------------------------------------------------


@pytest.mark.parametrize("deferred", [False, True])
def test_node_limit(deferred: bool) -> None:
    result = best_first_search(0, line_successors, lambda n: False, deferred=deferred, max_nodes=50)
    assert result.status is SearchStatus.NODE_LIMIT
    assert result.stats.expanded == 50
    assert result.plan is None and result.states is None and result.cost is None
    assert not result.solved()


def test_statuses_are_strings_with_the_plan_files_values() -> None:
    assert [str(status) for status in SearchStatus] == [
        "solved",
        "node-limit",
        "timeout",
        "exhausted",
        "unsolvable",
        "cancelled",
    ]
    assert SearchStatus.NODE_LIMIT == "node-limit" and SearchStatus("solved") is SearchStatus.SOLVED


def test_goal_found_when_limit_exactly_suffices() -> None:
    # Reaching 3 on the line with h = distance takes 3 expansions (0, 1, 2).
    h = lambda n: float(abs(3 - n))  # noqa: E731
    result = best_first_search(0, line_successors, lambda n: n == 3, h, max_nodes=3)
    assert result.solved() and result.plan == ("+", "+", "+")
    assert best_first_search(0, line_successors, lambda n: n == 3, h, max_nodes=2).status is (
        SearchStatus.NODE_LIMIT
    )


@pytest.mark.parametrize("deferred", [False, True])
def test_timeout_with_injected_clock(deferred: bool) -> None:
    clock = FakeClock(0.01)
    result = best_first_search(
        0,
        line_successors,
        lambda n: False,
        deferred=deferred,
        max_nodes=None,
        timeout=1.0,
        clock=clock,
    )
    assert result.status is SearchStatus.TIMEOUT
    assert result.stats.elapsed >= 1.0
    assert 0 < result.stats.expanded < 100


def test_timeout_with_real_clock_and_slow_successors() -> None:
    def slow(n: int) -> list[Edge[int, str]]:
        time.sleep(0.005)
        return line_successors(n)

    t0 = time.monotonic()
    result = best_first_search(0, slow, lambda n: False, max_nodes=None, timeout=0.05)
    assert result.status is SearchStatus.TIMEOUT
    assert time.monotonic() - t0 < 1.0


def test_unreachable_goal_is_exhausted_not_unsolvable() -> None:
    walls = frozenset({(4, 0), (5, 1)})  # seals off the corner (5, 0)
    grid = Grid(6, 4, walls)
    for deferred in (False, True):
        result = solve_grid(grid, (0, 0), (5, 0), deferred=deferred)
        assert result.status is SearchStatus.EXHAUSTED
        assert result.plan is None
        # The closest state reached is reported: two steps from the sealed corner.
        assert result.best in {(3, 0), (4, 1), (5, 2)}
        assert result.stats.best_h == 2.0
    reachable = 6 * 4 - len(walls) - 1  # every free cell except (5, 0)
    eager = solve_grid(Grid(6, 4, walls), (0, 0), (5, 0))
    assert eager.stats.expanded == reachable


def test_start_already_goal() -> None:
    calls: list[int] = []

    def successors(n: int) -> list[Edge[int, str]]:
        calls.append(n)
        return line_successors(n)

    for deferred in (False, True):
        result = best_first_search(7, successors, lambda n: n == 7, deferred=deferred)
        assert result.solved()
        assert result.plan == () and result.states == (7,) and result.cost == 0.0
        assert result.stats.expanded == 0
    assert calls == []


# -- pruning ---------------------------------------------------------------------------------------


@pytest.mark.parametrize("deferred", [False, True])
def test_no_prediction_is_counted_and_skipped(deferred: bool) -> None:
    failed = []

    def successors(n: int) -> list[Edge[int, str]]:
        def jump() -> int | None:
            failed.append(n)
            return None  # the "simulator" cannot predict the jump

        return [Edge("jump", 1.0, jump), Edge.known("step", 1.0, n + 1)]

    result = best_first_search(
        0, successors, lambda n: n == 10, lambda n: float(max(10 - n, 0)), deferred=deferred
    )
    assert result.solved() and result.plan == ("step",) * 10
    assert result.stats.no_prediction == len(failed) > 0
    if not deferred:
        # One jump per expansion, all evaluated at generation.
        assert result.stats.no_prediction == result.stats.expanded == 10


@pytest.mark.parametrize("deferred", [False, True])
def test_infinite_heuristic_prunes(deferred: bool) -> None:
    expanded: list[int] = []

    def successors(n: int) -> list[Edge[int, str]]:
        expanded.append(n)
        return line_successors(n)

    def h(n: int) -> float:
        return math.inf if n < 0 else float(abs(5 - n))

    result = best_first_search(
        0, successors, lambda n: n == 5, h, deferred=deferred, tie_break_seed=None
    )
    assert result.solved() and result.cost == 5.0
    assert result.stats.pruned_infinite >= 1
    assert all(n >= 0 for n in expanded)

    dead = best_first_search(-1, successors, lambda n: n == 5, h, deferred=deferred)
    assert dead.status is SearchStatus.EXHAUSTED
    assert dead.stats.pruned_infinite == 1 and dead.stats.expanded == 0


# -- dominance -------------------------------------------------------------------------------------

# A robot on a line 0..N with position uncertainty u: moving costs 1 and adds uncertainty (capped),
# "sense" costs 1 and resets it, "wait" costs 1 and adds uncertainty (never useful). The goal is
# to be at N with u = 0. A state with the same position and smaller uncertainty dominates.
N, U_MAX = 8, 4
Belief = tuple[int, int]


def belief_successors(s: Belief) -> list[Edge[Belief, str]]:
    pos, u = s
    grow = min(u + 1, U_MAX)
    edges = [Edge.known("sense", 1.0, (pos, 0)), Edge.known("wait", 1.0, (pos, grow))]
    if pos < N:
        edges.append(Edge.known("right", 1.0, (pos + 1, grow)))
    if pos > 0:
        edges.append(Edge.known("left", 1.0, (pos - 1, grow)))
    return edges


def belief_goal(s: Belief) -> bool:
    return s == (N, 0)


def replay_beliefs(plan: tuple[str, ...]) -> Belief:
    s: Belief = (0, 2)
    for action in plan:
        (s,) = [e.make_child() for e in belief_successors(s) if e.action == action]
    return s


@pytest.mark.parametrize("deferred", [False, True])
def test_dominance_pruning(deferred: bool) -> None:
    compared: list[tuple[Belief, Belief]] = []

    def dominates(a: Belief, b: Belief) -> bool:
        compared.append((a, b))
        return a[1] <= b[1]

    def run(**options) -> SearchResult[Belief, str]:
        return uniform_cost((0, 2), belief_successors, belief_goal, deferred=deferred, **options)

    plain = run()
    pruned = run(dominates=dominates, dominance_key=lambda s: s[0])
    thesis = run(dominates=dominates, dominance_key=lambda s: s[0], dominance_ignores_g=True)
    assert plain.cost == pruned.cost == N + 1  # g-aware dominance keeps optimality
    assert pruned.stats.expanded < plain.stats.expanded
    assert pruned.stats.pruned_dominated > 0
    assert thesis.stats.expanded <= pruned.stats.expanded
    for result in (plain, pruned, thesis):
        assert result.plan is not None and replay_beliefs(result.plan) == (N, 0)
    # Only states with equal keys (positions) were ever compared.
    assert compared and all(a[0] == b[0] for a, b in compared)


def test_dominance_respects_cost_unless_told_otherwise() -> None:
    # ("p", 0) is reached first but at cost 5; ("p", 1) later at cost 2. The thesis's rule
    # prunes the cheap one (it is dominated), the default keeps it because it is cheaper.
    graph = {
        ("s", 0): [(("a", 0), 1.0), (("b", 0), 1.5)],
        ("a", 0): [(("p", 0), 4.0)],
        ("b", 0): [(("p", 1), 0.5)],
        ("p", 0): [(("goal", 0), 1.0)],
        ("p", 1): [(("goal", 0), 1.0)],
        ("goal", 0): [],
    }

    def successors(s: Belief) -> list[Edge[Belief, str]]:
        return [Edge.known(f"to {t[0]}", c, t) for t, c in graph[s]]

    def run(**options) -> SearchResult[Belief, str]:
        return uniform_cost(
            ("s", 0),
            successors,
            lambda s: s[0] == "goal",
            dominates=lambda a, b: a[1] <= b[1],
            dominance_key=lambda s: s[0],
            **options,
        )

    safe, thesis = run(), run(dominance_ignores_g=True)
    assert safe.cost == 3.0 and safe.stats.pruned_dominated == 0
    assert thesis.cost == 6.0 and thesis.stats.pruned_dominated == 1


def test_state_reached_more_cheaply_is_not_dominated_by_itself() -> None:
    # Even under the thesis's rule a state never prunes its own cheaper copy: that is a
    # reopening, handled by duplicate detection.
    graph, h = _inconsistent_graph()
    result = astar(
        "S",
        graph_successors(graph),
        lambda s: s == "G",
        h.__getitem__,
        dominates=lambda a, b: True,
        dominance_key=lambda s: s,
        dominance_ignores_g=True,
    )
    assert result.cost == 6.0 and result.stats.reopened == 1
    assert result.stats.pruned_dominated == 0


def test_dominance_without_key_uses_one_bucket() -> None:
    result = uniform_cost(
        (0, 2), belief_successors, belief_goal, dominates=lambda a, b: a == (b[0], 0)
    )
    assert result.cost == N + 1


# -- tie-breaking ----------------------------------------------------------------------------------


@pytest.mark.parametrize("deferred", [False, True])
def test_tie_break_seed(deferred: bool) -> None:
    def plan_for(seed: int | None) -> tuple[str, ...]:
        result = solve_grid(Grid(6, 6), (0, 0), (5, 5), deferred=deferred, tie_break_seed=seed)
        assert result.cost == 10.0
        assert_valid_plan(Grid(6, 6), (0, 0), (5, 5), result)
        assert result.plan is not None
        return result.plan

    if not deferred:
        # Ties on f are broken towards smaller h, so on an open grid A* walks straight to the
        # goal: one expansion per step.
        grid = Grid(6, 6)
        assert solve_grid(grid, (0, 0), (5, 5), tie_break_seed=1).stats.expanded == 10
    assert plan_for(3) == plan_for(3)
    assert plan_for(None) == plan_for(None)
    assert len({plan_for(seed) for seed in range(8)}) >= 2


# -- callbacks -------------------------------------------------------------------------------------


def test_progress_callback() -> None:
    snapshots: list[SearchStats] = []
    result = uniform_cost(
        0, line_successors, lambda n: n == 60, progress=snapshots.append, clock=FakeClock(0.05)
    )
    assert result.solved()
    assert len(snapshots) >= 3
    assert snapshots[-1] == result.stats  # the final call carries the final statistics
    assert snapshots[0] is not result.stats  # snapshots are copies
    expanded = [s.expanded for s in snapshots]
    assert expanded == sorted(expanded)


@pytest.mark.parametrize("deferred", [False, True])
def test_should_stop_cancels(deferred: bool) -> None:
    polls = 0

    def should_stop() -> bool:
        nonlocal polls
        polls += 1
        return polls > 10

    result = best_first_search(
        0, line_successors, lambda n: False, deferred=deferred, should_stop=should_stop
    )
    assert result.status is SearchStatus.CANCELLED
    assert result.plan is None
    assert result.stats.expanded <= 10


def test_eager_stops_between_children_of_one_expansion() -> None:
    # Each child may be a long simulation: cancellation is honoured inside an expansion.
    polls = 0

    def should_stop() -> bool:
        nonlocal polls
        polls += 1
        return polls > 5

    wide = lambda n: [Edge.known(i, 1.0, n * 100 + i) for i in range(50)]  # noqa: E731
    result = best_first_search(0, wide, lambda n: False, should_stop=should_stop)
    assert result.status is SearchStatus.CANCELLED
    assert result.stats.expanded == 1
    assert result.stats.evaluated < 10 < 50


# -- API contracts ---------------------------------------------------------------------------------


def test_edge_known_and_result_invariants() -> None:
    edge = Edge.known("a", 2.0, "child")
    assert edge.make_child() == "child" and edge.cost == 2.0 and edge.action == "a"
    with pytest.raises(ValueError):
        SearchResult(SearchStatus.SOLVED, None, None, None, SearchStats())
    with pytest.raises(ValueError):
        SearchResult(SearchStatus.TIMEOUT, (), (0,), 0.0, SearchStats())
    with pytest.raises(ValueError):
        SearchResult(SearchStatus.SOLVED, ("a",), (0,), 1.0, SearchStats())


def test_invalid_arguments() -> None:
    with pytest.raises(ValueError):
        best_first_search(0, lambda n: [Edge.known("bad", -1.0, n + 1)], lambda n: n == 3)
    with pytest.raises(ValueError):
        best_first_search(0, line_successors, lambda n: n == 3, weight=-1.0)
    with pytest.raises(ValueError):
        best_first_search(0, line_successors, lambda n: n == 3, dominance_key=lambda n: n)
    with pytest.raises(ValueError):
        best_first_search(0, line_successors, lambda n: n == 3, lambda n: math.nan)


def test_options_as_one_value_and_as_overrides() -> None:
    options = SearchOptions[int, str](max_nodes=2, deferred=True)
    given = best_first_search(0, line_successors, lambda n: n == 3, options=options)
    named = best_first_search(0, line_successors, lambda n: n == 3, max_nodes=2, deferred=True)
    assert given.status is named.status is SearchStatus.NODE_LIMIT
    assert given.stats.expanded == named.stats.expanded == 2
    # an override replaces the one field, the others stay the options'
    more = best_first_search(0, line_successors, lambda n: n == 3, options=options, max_nodes=9)
    same = best_first_search(0, line_successors, lambda n: n == 3, max_nodes=9, deferred=True)
    eager = best_first_search(0, line_successors, lambda n: n == 3, max_nodes=9)
    assert more.solved() and more.plan == ("+", "+", "+")
    counts = [(r.stats.evaluated, r.stats.generated) for r in (more, same, eager)]
    assert counts[0] == counts[1] != counts[2]  # still deferred: fewer children evaluated
    with pytest.raises(ValueError, match="weight"):
        SearchOptions(weight=-1.0)
    with pytest.raises(TypeError):
        best_first_search(0, line_successors, lambda n: n == 3, max_node=2)


@pytest.mark.parametrize(("dead_ends", "evaluations"), [(2, 2), (3, 12)])
def test_dead_ends_are_remembered_in_a_bounded_recent_cache(
    monkeypatch: pytest.MonkeyPatch, dead_ends: int, evaluations: int
) -> None:
    """Each of the 12 steps of a line also leads to one of ``dead_ends`` dead ends, in turn.
    With room for two: two dead ends are evaluated once each; three, met in turn, each leave
    the cache before they come back, so every meeting evaluates the heuristic again. The
    search itself (plan, counts) is the same either way."""
    monkeypatch.setattr("arrange_up.search.DEAD_END_CACHE", 2)
    calls: list[object] = []

    def successors(n: object) -> list[Edge[object, str]]:
        assert isinstance(n, int)
        return [Edge.known("+", 1.0, n + 1), Edge.known("x", 1.0, ("dead", n % dead_ends))]

    def heuristic(s: object) -> float:
        if isinstance(s, tuple):
            calls.append(s)
            return math.inf
        return 0.0

    result = best_first_search(0, successors, lambda n: n == 12, heuristic)
    assert result.solved() and len(result.plan) == 12
    assert result.stats.pruned_infinite == 12
    assert len(calls) == evaluations
