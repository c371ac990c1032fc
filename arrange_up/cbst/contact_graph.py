"""Contact graphs of a push (thesis §3.2, Figures 3-2 to 3-4: MAKECG and PUSHTRANS).

Everything here works in the canonical frame of :mod:`arrange_up.cbst.frame`: the push goes
toward ``+u`` and the wall ahead (if any) is the line ``u = wall``. The caller maps the belief
into that frame, calls :func:`analyse_push` and maps the answer back; there is one
implementation for the four axis directions.

The graph
=========
A :class:`ContactGraph` with the node :data:`ROBOT` (the paddle), the node :data:`WALL` and
one node per object the push may move. MAKECG: starting from the robot, each node's belief
bounding box (its shadow box) is swept toward ``+u`` up to the wall; every object whose box
overlaps the swept volume and that may lie *in front of* it gets an edge; every node gets an
edge to the wall (Figure 3-3). An edge carries ``certain=True`` when the contact happens in
every state of the belief (the two shapes' ``v`` spans overlap by at least
:data:`MIN_OVERLAP`, :data:`MIN_OVERLAP_PADDLE` for the paddle, whatever the poses), else
``certain=False`` (a possible, grazing contact).

Pairs whose boxes overlap but that cannot be in front of each other in any state (their
``u`` position ranges are less than a block apart: by the non-collision constraint they are
side by side, as in adjacent rows of an arrangement) get no edge: a push slides them along
each other.

Paths and predictability
========================
Maximal ``ROBOT -> WALL`` paths are the trains of objects the paddle compresses against the
wall. The push is predicted when

* there is a wall ahead, and every reached node is a block of the model's size (no other
  shapes, no obstacles in any swept volume);
* every object lies at one *depth* (its number of objects to the wall) on every maximal path
  through it, and an object on a longest path is on no shorter one;
* **the uneven-length rule**: a shorter maximal path is ignored only when the paddle provably
  cannot reach its first object: the closest the paddle's front gets to the wall is
  ``wall - n * d`` (``n`` objects of width ``d`` on the longest path), plus the spread of its
  tilted front and a margin; the object's rear (its shadow's ``umin``) must lie beyond that;
* every object on a longest path has a *certain* contact ahead (an object one shallower, or
  the wall), else it may slide past what should stop it; and a *certain* contact from behind
  (the paddle or an object one deeper), else it may or may not be pushed. The one exception
  is a *grazed* object (:class:`Member`): already flush (within :data:`FLUSH_TOLERANCE` of
  its ``x_max``), with only possible contacts behind, all from objects (corners of a
  neighbouring row sliding past). A touch cannot move it forward, so the caller keeps its
  box, extended forward to ``x_max`` plus the contact slop and sideways by the largest
  overlap of a grazer's shadow box with its own (a corner sliding past cannot push it
  aside further than it overlaps it);
* the commanded push reaches the compressed train: the paddle's reference front, less its pose
  uncertainty along the push, lies at least :data:`PUSH_MARGIN` beyond ``wall - n * d``.

Anything else answers "no prediction" with a reason. A push whose paddle sweep (its commanded
travel) touches no object leaves the belief unchanged.

A :class:`PushMemo` passed to :func:`analyse_push` remembers the graph's rows per scene and
the structure per push and reached nodes, for the many pushes of a search.

Paths of equal length may share objects (two rows pushed together, with grazing contacts
between the rows): the depths make the result well defined, and the caller predicts each
object from each of its certain (previous, next) neighbour pairs and keeps the largest
uncertainty.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

from arrange_up.geometry.shapes import Box, HalfWidths, Pose, boxes_overlap

__all__ = [
    "FRONT_TOLERANCE",
    "MIN_OVERLAP",
    "MIN_OVERLAP_PADDLE",
    "PUSH_MARGIN",
    "REACH_MARGIN",
    "ROBOT",
    "WALL",
    "ContactGraph",
    "Member",
    "Node",
    "Paddle",
    "PushMemo",
    "PushStructure",
    "analyse_push",
    "make_contact_graph",
    "maximal_paths",
]

#: Smallest overlap (inches) of two blocks' spans across the push that makes their contact
#: *certain*: the front one is then squarely in the way. Trains whose weakest contact overlaps
#: by less buckle (a block squeezes out sideways) more often, the less it overlaps (the
#: figures: docs/cbst.md, "Training data").
MIN_OVERLAP = 0.4
#: The same for the paddle's contact with the first object of a train (inches): the wide,
#: rigid paddle does not buckle, it only has to be sure to hit the object.
MIN_OVERLAP_PADDLE = 0.25
#: How far beyond the fully compressed train the paddle's commanded front must reach (inches).
PUSH_MARGIN = 0.05
#: Added to the paddle's closest approach in the uneven-length rule (inches): contact slop of
#: the physics and rounding.
REACH_MARGIN = 0.05
#: A pair is "in front" of each other when their position ranges allow a separation along the
#: push of at least one block width less this tolerance (inches).
FRONT_TOLERANCE = 0.02
#: An object whose position range already reaches within this distance (inches) of its
#: ``x_max`` is *flush*: a push cannot move it forward by more than the contact slop.
FLUSH_TOLERANCE = 0.02
#: Most ``ROBOT -> WALL`` paths enumerated (the graph is a DAG; dense scenes could have
#: exponentially many); beyond it the push is not predicted.
MAX_PATHS = 5000


@dataclass(frozen=True)
class _Terminal:
    label: str

    def __repr__(self) -> str:
        return self.label


#: The robot (paddle) node. A sentinel object, so no object name can collide with it.
ROBOT = _Terminal("R")
#: The wall node.
WALL = _Terminal("W")


@dataclass(frozen=True)
class Node:
    """One object's belief in the canonical frame: ``center ± half`` and its shadow ``box``
    ``(umin, vmin, umax, vmax)``; ``block`` is True for a square block the model applies to."""

    name: str
    center: Pose
    half: HalfWidths
    box: Box
    block: bool = True


@dataclass(frozen=True)
class Paddle:
    """The manipulator in the canonical frame: commanded approach ``center`` with pose
    uncertainty ``half``, its shadow ``box``, its flat ``length`` (across the push) and
    ``thickness`` (along it), and the commanded ``travel`` along ``+u``."""

    center: Pose
    half: HalfWidths
    box: Box
    length: float
    thickness: float
    travel: float

    @property
    def tilt_spread(self) -> float:
        """How far (along ``u``) one point of the front can lead another when the paddle is
        turned by up to its angle uncertainty."""
        t = min(abs(self.half[2]), 0.5 * math.pi)
        return self.length * math.sin(t) + self.thickness * (1.0 - math.cos(t))

    @property
    def reach_box(self) -> Box:
        """The region the paddle's shadow sweeps over its commanded travel."""
        umin, vmin, umax, vmax = self.box
        return (umin, vmin, umax + max(0.0, self.travel), vmax)


@dataclass(frozen=True)
class Member:
    """An object of a compressed train: its ``depth`` (1 = touching the wall) and its
    certain neighbours behind (``prevs``: :data:`ROBOT` or object names) and ahead
    (``nexts``: :data:`WALL` or object names).

    A *grazed* member has no certain contact behind, only possible ones from objects
    (``grazers``), and is already flush: it is either left alone or touched by a corner
    sliding past; ``graze`` (inches) is the largest overlap across the push of a grazer's
    shadow box with its own, which bounds how far the corner can push it aside.
    """

    name: str
    depth: int
    prevs: tuple[object, ...]
    nexts: tuple[object, ...]
    grazers: tuple[str, ...] = ()
    graze: float = 0.0

    @property
    def grazed(self) -> bool:
        return bool(self.grazers)


@dataclass(frozen=True)
class PushStructure:
    """What a push does to the belief, structurally.

    ``kind`` is ``"unchanged"`` (the paddle touches nothing), ``"predict"`` (``members`` are
    the objects to update, ``length`` the number of objects on the longest train) or
    ``"none"`` (no prediction; ``reason`` says why).
    """

    kind: str
    reason: str = ""
    members: tuple[Member, ...] = ()
    length: int = 0
    untouched: frozenset[str] = field(default_factory=frozenset)

    @property
    def predictable(self) -> bool:
        return self.kind != "none"


class Unpredictable(Exception):
    """Raised inside the analysis; turned into ``PushStructure(kind="none", reason=...)``."""


class ContactGraph:
    """A directed graph whose every edge ``a -> b`` carries whether the contact is certain.

    Nodes are kept in the order they were first met, and each node's successors and
    predecessors in the order their edges were added, so every walk over the graph is
    deterministic. (A plain pair of dicts: building a general graph library's digraph took
    a third of a CBST push's analysis.)
    """

    __slots__ = ("_ahead", "_behind")

    def __init__(self) -> None:
        self._ahead: dict[object, dict[object, bool]] = {}
        self._behind: dict[object, dict[object, bool]] = {}

    def add_node(self, node: object) -> None:
        self._ahead.setdefault(node, {})
        self._behind.setdefault(node, {})

    @property
    def nodes(self) -> list[object]:
        return list(self._ahead)

    def __contains__(self, node: object) -> bool:
        return node in self._ahead

    def has_edge(self, a: object, b: object) -> bool:
        return b in self._ahead.get(a, ())

    def certain(self, a: object, b: object) -> bool:
        """Whether the contact ``a -> b`` is certain (``KeyError`` if there is no edge)."""
        return self._ahead[a][b]

    def successors(self, node: object) -> tuple[object, ...]:
        return tuple(self._ahead[node])

    def predecessors(self, node: object) -> tuple[object, ...]:
        return tuple(self._behind[node])


# -- pair relations ------------------------------------------------------------------------------
def _swept(box: Box, end: float) -> Box:
    umin, vmin, umax, vmax = box
    return (umin, vmin, max(umax, end), vmax)


def _contact(a: Node | Paddle, b: Node, block_size: float) -> bool | None:
    """The edge ``a -> b`` of a ``b`` whose box overlaps ``a``'s box swept up to the wall:
    None (no contact), False (possible) or True (certain).

    Raises :class:`Unpredictable` when the order of the two along the push is undecided.
    """
    d = block_size
    dv = abs(b.center[1] - a.center[1])
    if isinstance(a, Paddle):
        reach = 0.5 * a.length + 0.5 * d
        return reach - (dv + a.half[1] + b.half[1]) >= MIN_OVERLAP_PADDLE
    du = b.center[0] - a.center[0]
    # Largest separation along the push that the position ranges allow.
    if abs(du) <= 1e-9:
        if (abs(du) + a.half[0] + b.half[0]) >= d - FRONT_TOLERANCE:
            raise Unpredictable(
                f"the order of {a.name!r} and {b.name!r} along the push is not determined"
            )
        return None  # side by side in every state
    if du < 0.0:
        return None  # b is behind a: the edge b -> a is decided from b's side
    if (b.center[0] + b.half[0]) - (a.center[0] - a.half[0]) < d - FRONT_TOLERANCE:
        return None  # never a block length apart: side by side (non-collision constraint)
    return d - (dv + a.half[1] + b.half[1]) >= MIN_OVERLAP


def _flush(node: Node, x_max: float) -> bool:
    """Whether ``node`` is *flush*: its position range along the push reaches within
    :data:`FLUSH_TOLERANCE` of ``x_max``, so a push cannot move it forward by more than the
    contact slop (a condition of a grazed object)."""
    return node.center[0] + node.half[0] >= x_max - FLUSH_TOLERANCE


def _shadow_overlap(a: Node, b: Node) -> float:
    """The overlap across the push (inches) of two objects' shadow boxes: a bound on how far
    a corner of ``a`` sliding past can push ``b`` aside (rotation included)."""
    return max(0.0, min(a.box[3], b.box[3]) - max(a.box[1], b.box[1]))


# -- MAKECG --------------------------------------------------------------------------------------
#: A row of the contact graph: the edges out of one node, ``(i, certain)`` to the scene's
#: ``i``-th node in the scene's order, ended by a reason (a string) when meeting the next node
#: (or an obstacle) makes the push unpredictable once the row's node is reached. (Indices, not
#: nodes: rows of numbers and flags are left alone by the garbage collector.)
_Row = tuple[object, ...]


def _contact_row(
    current: Node | Paddle,
    nodes: Sequence[Node],
    end: float,
    block_size: float,
    obstacles: Sequence[Box],
) -> _Row:
    """The edges out of ``current`` to the ``nodes`` whose box overlaps ``current``'s box
    swept up to ``end`` (see :data:`_Row`)."""
    source = ROBOT if isinstance(current, Paddle) else current.name
    swept = _swept(current.box, end)
    for box in obstacles:
        if boxes_overlap(box, swept):
            return ("an obstacle lies in the path of the push",)
    u0, v0, u1, v1 = swept
    row: list[object] = []
    for i, other in enumerate(nodes):
        if other.name == source:
            continue
        # boxes_overlap(other.box, swept), written out: this loop is a CBST search's hottest
        b0, b1, b2, b3 = other.box
        if not (
            (u1 if u1 < b2 else b2) - (u0 if u0 > b0 else b0) > 0.0
            and (v1 if v1 < b3 else b3) - (v0 if v0 > b1 else b1) > 0.0
        ):
            continue
        try:
            certain = _contact(current, other, block_size)
        except Unpredictable as why:
            return (*row, str(why))
        if certain is None:
            continue
        if not other.block:
            return (*row, f"{other.name!r} may be pushed and is not a block")
        row.append((i, certain))
    return tuple(row)


def _build(
    paddle: Paddle,
    nodes: Sequence[Node],
    wall: float | None,
    block_size: float,
    obstacles: Sequence[Box],
    rows: dict[str, _Row] | None,
) -> tuple[ContactGraph, list[Node]]:
    """MAKECG: the graph and the reached nodes in the order they were met. ``rows``, the
    objects' rows (:func:`_contact_row`) of this scene known so far, is read and filled."""
    end = wall if wall is not None else math.inf
    graph = ContactGraph()
    graph.add_node(ROBOT)
    if wall is not None:
        graph.add_node(WALL)
    # the graph's own tables, filled here directly: this is the hot loop of a CBST search
    ahead, behind = graph._ahead, graph._behind
    agenda: list[Node | Paddle] = [paddle]
    reached: list[Node] = []
    while agenda:
        current = agenda.pop()
        if isinstance(current, Paddle):
            source: object = ROBOT
            row = _contact_row(current, nodes, end, block_size, obstacles)
        else:
            source = current.name
            row = rows.get(source) if rows is not None else None
            if row is None:
                row = _contact_row(current, nodes, end, block_size, obstacles)
                if rows is not None:
                    rows[source] = row
        out = ahead[source]
        for entry in row:
            if isinstance(entry, str):
                raise Unpredictable(entry)
            i, certain = entry
            other = nodes[i]
            name = other.name
            if name not in ahead:
                reached.append(other)
                agenda.append(other)
                ahead[name], behind[name] = {}, {}
            out[name] = certain
            behind[name][source] = certain
        if wall is not None:
            out[WALL] = True
            behind[WALL][source] = True
    return graph, reached


def make_contact_graph(
    paddle: Paddle,
    nodes: Sequence[Node],
    *,
    wall: float | None,
    block_size: float,
    obstacles: Sequence[Box] = (),
) -> ContactGraph:
    """MAKECG (Figure 3-4) in the canonical frame.

    Returns the graph of the nodes reachable from :data:`ROBOT`; edges carry ``certain``.
    Raises :class:`Unpredictable` for an obstacle in a swept volume, an undecided order,
    or a reached object that is not a block.
    """
    return _build(paddle, nodes, wall, block_size, obstacles, None)[0]


def maximal_paths(graph: ContactGraph) -> list[tuple[object, ...]]:
    """The ``ROBOT -> WALL`` paths not contained in another one, longest first (ties in a
    fixed order). Raises :class:`Unpredictable` beyond :data:`MAX_PATHS` paths."""
    if WALL not in graph:
        return []
    # A path contained in another is strictly shorter, so each is tested against the longer
    # paths kept so far only.
    # (the walk lists each path once, and no two paths share a key: a total order)
    label = {node: repr(node) for node in graph.nodes}
    paths = sorted(_paths_to_wall(graph), key=lambda p: (-len(p), [label[n] for n in p]))
    kept: list[tuple[object, ...]] = []
    kept_sets: list[frozenset[object]] = []
    for path in paths:
        members = frozenset(path)
        if not any(members < longer for longer in kept_sets):
            kept.append(path)
            kept_sets.append(members)
    return kept


def _paths_to_wall(graph: ContactGraph) -> list[tuple[object, ...]]:
    """The ``ROBOT -> WALL`` paths of the contact graph that may be maximal: those whose last
    object touches nothing but the wall, by a depth-first walk over its adjacency.

    Every edge points forward along the push (an object's contacts are only with what lies
    ahead of it), so the graph is acyclic and every path is simple. Every node has an edge to
    the wall, so every path from the robot is a path to the wall; one that ends at an object
    with an object ahead is contained in its own extension, hence never maximal, and is only
    counted (for :data:`MAX_PATHS`, which counts every path), not kept. (The generic
    simple-path enumeration of networkx spent most of a CBST push's analysis on bookkeeping
    that this needs not.)"""
    successors = graph._ahead  # read in place: each node's successors in their order
    paths: list[tuple[object, ...]] = []
    found = 0
    stack: list[tuple[object, ...]] = [(ROBOT,)]
    while stack:
        path = stack.pop()
        ahead = successors[path[-1]]
        for nxt in ahead:
            if nxt is WALL:
                found += 1
                if found > MAX_PATHS:
                    raise Unpredictable("too many contact paths to analyse")
                if len(ahead) == 1:
                    paths.append((*path, WALL))
            elif nxt not in path:
                stack.append((*path, nxt))
    return paths


def _longest_train(graph: ContactGraph) -> int:
    """The number of objects on the longest ``ROBOT -> WALL`` path (the graph is acyclic: each
    node's longest train ahead is worked out once, deepest first)."""
    ahead: dict[object, int] = {}
    successors = graph._ahead  # read in place: each node's successors in their order
    stack: list[tuple[object, bool]] = [(ROBOT, False)]
    while stack:
        node, done = stack.pop()
        if node in ahead:
            continue
        objects = [n for n in successors[node] if n is not WALL]
        if done:
            ahead[node] = max((1 + ahead[n] for n in objects), default=0)
            continue
        stack.append((node, True))
        stack.extend((n, False) for n in objects if n not in ahead)
    return ahead[ROBOT]


# -- PUSHTRANS (structure) -----------------------------------------------------------------------
class PushMemo:
    """What :func:`analyse_push` worked out for one search, remembered for its next pushes.

    A search meets the same objects' beliefs in many beliefs, and one belief's pushes share
    its scene. So this remembers, per scene (the nodes, the wall, the obstacles), the rows of
    the contact graph (each object's edges), which all pushes in that scene's direction
    share; and per push (the paddle, the wall, the obstacles and the nodes it reached), the
    structure, which depends on nothing else. A push met again in another scene whose reached
    nodes are the same is answered with the same :class:`PushStructure` object. Nodes are
    keyed by identity (the memo holds them, so no identity is reused while it is kept):
    callers that keep each belief's node (as the CBST semantics does) find their scenes.
    Past ``limit`` entries a table starts again empty; a copy (pickled) starts empty.
    """

    def __init__(self, limit: int = 100_000) -> None:
        self.limit = limit
        self._scenes: dict[tuple, tuple[tuple[Node, ...], dict[str, _Row]]] = {}
        self._structures: dict[tuple, tuple[tuple[Node, ...], PushStructure]] = {}

    def __getstate__(self) -> dict[str, int]:
        # the tables are keyed by identities, which mean nothing in another process
        return {"limit": self.limit}

    def __setstate__(self, state: dict[str, int]) -> None:
        self.__init__(state["limit"])

    def rows(self, nodes: Sequence[Node], key: tuple) -> dict[str, _Row]:
        """The rows known so far of the scene of ``nodes`` (``key``: its wall and the rest)."""
        scene = (*key, *map(id, nodes))
        known = self._scenes.get(scene)
        if known is None:
            if len(self._scenes) >= self.limit:
                self._scenes.clear()
            known = self._scenes[scene] = (tuple(nodes), {})
        return known[1]

    def structure(self, reached: Sequence[Node], key: tuple, analyse) -> PushStructure:
        """The structure of the push ``key`` (its paddle, wall and the rest) that reached
        ``reached``: remembered, or ``analyse()``'s."""
        push = (*key, *map(id, reached))
        known = self._structures.get(push)
        if known is None:
            if len(self._structures) >= self.limit:
                self._structures.clear()
            known = self._structures[push] = (tuple(reached), analyse())
        return known[1]


def analyse_push(
    paddle: Paddle,
    nodes: Sequence[Node],
    *,
    wall: float | None,
    block_size: float,
    obstacles: Sequence[Box] = (),
    memo: PushMemo | None = None,
) -> PushStructure:
    """Decide what a push does (see the module docstring): unchanged, the trains to predict,
    or no prediction with a reason. With ``memo``, what it remembers is used and added to
    (the same answers as without)."""
    reach = paddle.reach_box
    if not any(boxes_overlap(node.box, reach) for node in nodes):
        return PushStructure("unchanged")
    scene = (wall, block_size, tuple(obstacles))
    try:
        rows = memo.rows(nodes, scene) if memo is not None else None
        graph, reached = _build(paddle, nodes, wall, block_size, obstacles, rows)
    except Unpredictable as why:
        return PushStructure("none", reason=str(why))

    def analyse() -> PushStructure:
        try:
            return _analyse(graph, paddle, reached, wall, block_size)
        except Unpredictable as why:
            return PushStructure("none", reason=str(why))

    if memo is None:
        return analyse()
    return memo.structure(reached, (paddle, *scene), analyse)


def _analyse(graph, paddle, reached, wall, block_size) -> PushStructure:
    """PUSHTRANS's structure from the contact graph and its ``reached`` nodes."""
    if wall is None:
        raise Unpredictable("no wall ahead: the pushed objects are not stopped")
    # The reach test needs only the longest train, found without listing the paths: most
    # pushes a search refuses fail it, and listing the paths is the costly part.
    length = _longest_train(graph)
    front = paddle.center[0] + 0.5 * paddle.thickness + paddle.travel - paddle.half[0]
    if front < wall - length * block_size + PUSH_MARGIN:
        raise Unpredictable("the push stops short of compressing the train against the wall")
    paths = maximal_paths(graph)
    assert len(paths[0]) - 2 == length
    depth: dict[str, int] = {}
    on_long: set[str] = set()
    for path in paths:
        objects = path[1:-1]
        for i, name in enumerate(objects):
            k = len(objects) - i
            if depth.setdefault(name, k) != k:
                raise Unpredictable(f"{name!r} lies at different distances from the wall")
            if len(objects) == length:
                on_long.add(name)
    d = block_size
    by_name = {node.name: node for node in reached}
    closest = wall - length * d + paddle.tilt_spread + REACH_MARGIN
    for path in paths:
        objects = path[1:-1]
        if len(objects) == length:
            continue
        if any(name in on_long for name in objects):
            raise Unpredictable(f"{objects[0]!r} lies on trains of different lengths")
        first = by_name[objects[0]]
        if first.box[0] <= closest:
            raise Unpredictable(
                f"the paddle may reach {objects[0]!r}, whose train is shorter than the longest"
            )
    members = []
    for name in sorted(on_long, key=lambda n: (-depth[n], n)):
        k = depth[name]
        prevs = tuple(
            p
            for p in graph.predecessors(name)
            if graph.certain(p, name)
            and ((p is ROBOT and k == length) or (p is not ROBOT and depth.get(p) == k + 1))
        )
        nexts = tuple(
            q
            for q in graph.successors(name)
            if graph.certain(name, q)
            and ((q is WALL and k == 1) or (q is not WALL and depth.get(q) == k - 1))
        )
        if not nexts:
            raise Unpredictable(f"{name!r} may slide past what is ahead (no certain contact)")
        nexts = tuple(sorted(nexts, key=repr))
        if prevs:
            members.append(Member(name, k, tuple(sorted(prevs, key=repr)), nexts))
            continue
        # Only possible contacts behind: the object may or may not be touched. That is
        # predictable when it is already flush (a touch cannot move it forward) and only
        # objects (corners sliding past, not the paddle) may touch it.
        node = by_name[name]
        x_max = wall - (k - 0.5) * d
        grazers = tuple(sorted(p for p in graph.predecessors(name) if p is not ROBOT))
        flush = _flush(node, x_max)
        paddle_may_touch = k == length and graph.has_edge(ROBOT, name)
        if not grazers or not flush or paddle_may_touch:
            raise Unpredictable(f"{name!r} may or may not be pushed (no certain contact behind)")
        graze = max(_shadow_overlap(by_name[g], node) for g in grazers)
        members.append(Member(name, k, (), nexts, grazers, graze))
    untouched = frozenset(node.name for node in reached if node.name not in on_long)
    return PushStructure(
        "predict",
        members=tuple(members),
        length=length,
        untouched=untouched,
    )
