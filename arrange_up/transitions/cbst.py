"""Composable belief-state transitions (CBST, thesis §3.2) on factored interval beliefs.

Beliefs are :class:`~arrange_up.belief.states.IntervalBelief`: one box ``center ± half`` in
``(x, y, theta)`` per object on the table, in the problem's object order, rounded to 1e-6
(angles wrapped into each object's symmetry period around its reference) so that equal
outcomes compare and hash equal and the search dedupes them.

* **initial belief**: the problem's initial poses and uncertainties.
* **place**: the object's box is the commanded pose ± the place uncertainty.
* **pick**: the object is removed.
* **a fixture as a wall**: the nearest fixture on the table ahead of the paddle, across its
  sweep, stands in for the wall ahead (a fence the planner put down:
  :mod:`arrange_up.planning.fences`) when its nominal footprint spans the centre of every
  block of the compressed train across the push, with a quarter block to spare on either side
  (else no prediction, :data:`FIXTURE_REFUSAL`). Its face is as
  uncertain as its place: the train is composed from the nominal face, and every predicted
  ``u`` range is widened on both sides by how far the face's shadow reaches beyond the nominal
  face (the fixture's place noise and turn). The model was trained against rigid table walls;
  a clamped fixture is one (the physics holds it still), at an uncertain pose.
* **push**: the belief is mapped into the canonical "push toward +u" frame
  (:class:`~arrange_up.cbst.frame.CanonicalFrame`), the contact graph decides what moves
  (:func:`~arrange_up.cbst.contact_graph.analyse_push`), and every object of the compressed
  train(s) gets its new box from the learned PREDICT (a model trained under the problem's
  controller: :func:`~arrange_up.cbst.choice.model_for`) composed from the wall back toward
  the paddle (PUSHTRANSOBJ): an object at depth ``k``
  (``k`` objects from the wall, itself included) ends with ``u`` in
  ``[x_max - dx, x_max + max(slip, allowance_k)]``, ``x_max = wall - (k - 1/2) d`` (the
  thesis's ``b[next].x - d`` with ``next`` flush and as far forward as possible), ``v`` in
  ``v ± dy`` about its unchanged centre (clipped to the walls beside the push), and angle
  ``0 ± dth`` in the canonical frame. A *grazed* object (already flush, touched at most by
  a corner of a neighbouring row sliding past) keeps its box, extended forward to ``x_max``
  plus the slop allowance and sideways by the grazer's largest overlap, but by no more than
  the controller's :data:`GRAZE_ALLOWANCE`. Objects the push
  cannot reach are unchanged; a push
  whose paddle sweep touches nothing returns the belief itself.

The features of every object come from the belief *before* the push (as in the training
data), so all of a push's predictions are one batched call of the fast forest, made for the
rows the semantics has not met before: a row's answer (its prediction, or that it lies outside
the training domain) is remembered, since a search meets the same rows in many beliefs. So are
a push's paddle, the contact graph's rows and structures
(:class:`~arrange_up.cbst.contact_graph.PushMemo`) and a push's outcome per structure: a push
met again whose paddle reaches the same objects' beliefs changes them as it did before.

A push returns ``None`` (no prediction) whenever the contact graph says so (see
:mod:`arrange_up.cbst.contact_graph`), when the push is not axis-aligned, when the
manipulator or a pushed object is not the paddle/block the model was trained on, when a
feature lies outside the training domain, or when the model predicts that the train may
buckle (predicted ``slip`` above :data:`~arrange_up.cbst.features.BUCKLE_LIMIT`), and, for a
model trained on the planner's pushes to the wall (its card's ``wall_push`` is ``"planner"``,
:mod:`arrange_up.cbst.data`), when the push sends the paddle elsewhere than those did
(:data:`TRAINED_PUSH_REFUSAL`): such a model knows that push only.
``reasons`` counts the reasons, for diagnostics.

Where the problem's controller has a **simulated fallback** (:data:`FALLBACK_PARTICLES`: the
compliant controller's), such a push is not refused but answered by the physics
(:class:`~arrange_up.transitions.fallback.SimulatedFallback`: states drawn from the interval
belief, pushed, the boxes rebuilt from their ends); it is refused only when the physics refuses
it too (a part pushed off the table, a simulation not at rest), under the physics' reason.
``fallback_reasons`` counts why the model refused the pushes that fell back, and
:meth:`CBSTSemantics.fallback_counts` how many fell back of all the pushes asked for.

``simulations`` counts model predictions: one per feature row evaluated (one PREDICT of the
thesis; an object with several certain neighbours on either side takes one per pair).
"""

from __future__ import annotations

import math
from collections import Counter
from functools import partial
from pathlib import Path

import numpy as np

from arrange_up.belief.compiled import compile_problem
from arrange_up.belief.states import IntervalBelief, ObjectInterval, wrap_angle
from arrange_up.cbst.choice import model_for
from arrange_up.cbst.contact_graph import (
    ROBOT,
    WALL,
    Node,
    Paddle,
    PushMemo,
    PushStructure,
    analyse_push,
)
from arrange_up.cbst.data import DEFAULT_GENERATION, GenerationSettings
from arrange_up.cbst.features import BUCKLE_LIMIT, feature_row
from arrange_up.cbst.frame import CanonicalFrame
from arrange_up.cbst.store import DEFAULT_MODEL
from arrange_up.geometry.se2 import rotate
from arrange_up.model.problem import (
    ArrangementProblem,
    ControllerKind,
    HalfWidths,
    ObjectKind,
    Pose,
)
from arrange_up.model.world import Action, Pick, Place, Push
from arrange_up.physics.stall import wall_overdrive, wall_push_front
from arrange_up.transitions.fallback import SimulatedFallback

__all__ = ["FALLBACK_PARTICLES", "GRAZE_ALLOWANCE", "CBSTSemantics"]

#: Why a push towards a fixture has no prediction when the fixture cannot stand in for a wall.
FIXTURE_REFUSAL = "a pushed object may slip past the end of a fixture ahead"
#: Distinct feature rows whose prediction a semantics remembers (about 100 bytes each); past
#: it the memory starts again empty.
PREDICTION_CACHE = 200_000
#: Contact-graph nodes (an object's belief in a push's frame) a semantics remembers.
NODE_CACHE = 100_000
#: Pushes' outcomes (and scenes, structures: :class:`~arrange_up.cbst.contact_graph.PushMemo`)
#: a semantics remembers.
OUTCOME_CACHE = 100_000
#: Shapes and sizes are compared with this tolerance (inches).
_SIZE_TOL = 1e-6
#: Why a push has no prediction from a model trained on the planner's pushes to the wall
#: (``wall_push="planner"``) when it sends the paddle elsewhere: the model knows no other push.
TRAINED_PUSH_REFUSAL = "the push sends the paddle elsewhere than the model's training pushes"
#: How far (in) a push's commanded front may lie from where such a model's training pushes
#: sent it: the rounding of generated poses (1e-6 in) and distances (1e-4 in), with room.
TRAINED_PUSH_TOLERANCE = 1e-3


#: How far (in) a grazed object's box is widened across the push at most, per controller kind:
#: the 99th percentile, rounded up to 0.01 in, of how far generated grazes moved the grazed
#: block beyond its box across the push (2000 scenes, seed 0; seed 1 as a fresh check), where
#: the grazer's overlap, a bound only for a corner sliding straight past, was several times as
#: wide (docs/cbst-models.md, "How far the predictions hold": `python benchmarks/cbst_graze.py
#: scenes`). Like PREDICT's boxes, an allowance measured in simulation, not a bound: a plan is
#: checked on rollouts (:mod:`arrange_up.planning.validation`).
GRAZE_ALLOWANCE: dict[ControllerKind, float] = {
    ControllerKind.COMPLIANT: 0.09,
    ControllerKind.SERVO: 0.12,
}

#: States the simulated fallback draws from the interval belief of a push the model refuses
#: (:mod:`arrange_up.transitions.fallback`), per controller kind; 0: no fallback, the push is
#: refused. The servo's model predicts the pushes its plans need (docs/cbst.md), and its plans
#: stay the model's; the compliant model refuses pushes the compliant plans need (its training
#: domain, pushes that stop short, trains that may slide), so the physics answers them.
FALLBACK_PARTICLES: dict[ControllerKind, int] = {
    ControllerKind.COMPLIANT: 8,
    ControllerKind.SERVO: 0,
}

#: What a predictable push does (:meth:`CBSTSemantics._outcome`): the reason it has no
#: prediction after all (None if it has one), its members' new intervals and the number of
#: model predictions it took.
_Outcome = tuple[str | None, dict[str, ObjectInterval], int]


def _r(value: float) -> float:
    return round(float(value), 6) + 0.0


class CBSTSemantics:
    """CBST over interval beliefs (see the module docstring).

    ``particles`` is 2: the planner sees an interval belief as its two corner
    pseudo-particles. ``seed`` and ``workers`` are accepted for the registry's signature and
    unused (predictions are deterministic and run in this process). ``model`` names the
    learned model (a shipped name, ``"default"`` for the shipped model of the problem's
    controller, or a card path); a model trained under another controller than the
    problem's is refused with ``ValueError`` (:func:`arrange_up.cbst.choice.model_for`).
    """

    name = "cbst"
    #: The contact graph refuses a push whose paddle may or may not touch a block, so the
    #: planner also proposes paddle positions that avoid such contacts.
    refuses_uncertain_contacts = True
    simulates_pushes = False  # a learned prediction (see transitions.Semantics)

    def __init__(
        self,
        problem: ArrangementProblem,
        *,
        particles: int = 2,
        seed: int = 0,
        workers: int = 1,
        model: str | Path = DEFAULT_MODEL,
    ) -> None:
        self.problem = problem
        self.particles = 2
        self.seed = seed
        self.workers = workers
        self.simulations = 0
        self._predictions: dict[tuple[float, ...], np.ndarray | None] = {}
        self._nodes: dict[tuple[str, str, ObjectInterval], Node] = {}
        self._paddles: dict[Push, tuple[CanonicalFrame | None, Paddle | None]] = {}
        self._last_nodes: dict[str, tuple[IntervalBelief, list[Node]]] = {}
        self._memo = PushMemo(OUTCOME_CACHE)
        self._outcomes: dict[tuple, tuple[PushStructure, _Outcome]] = {}
        self.reasons: Counter[str] = Counter()
        self.model = model_for(problem, model)  # trained under the problem's controller
        fallback_particles = FALLBACK_PARTICLES[problem.controller.kind]
        self.fallback = (
            SimulatedFallback(problem, particles=fallback_particles, seed=seed)
            if fallback_particles
            else None
        )
        #: No place rings where the fallback answers (see transitions.Semantics).
        self.place_rings = self.fallback is None
        #: Push transitions asked for, and those the simulated fallback answered.
        self.pushes = 0
        self.fallbacks = 0
        #: Why the model refused the pushes the fallback was asked for (answered or not), as
        #: :attr:`reasons` counts the refusals.
        self.fallback_reasons: Counter[str] = Counter()
        self.graze_allowance = GRAZE_ALLOWANCE[problem.controller.kind]
        card = self.model.card_
        self.block_size = float(card["block_size"])
        self.paddle_size = tuple(float(v) for v in card["paddle_size"])
        self.domain = self.model.domain_
        allowance = {int(k): float(v) for k, v in card["overshoot_allowance"].items()}
        self._allowance = allowance
        self._allowance_rate = max((v / k for k, v in allowance.items()), default=0.0)
        # What the training pushes were (a card without settings predates them: uniform).
        recorded = card.get("data", {}).get("settings")
        settings = GenerationSettings.from_dict(recorded) if recorded else DEFAULT_GENERATION
        self._trained_wall_push = settings.wall_push
        self._trained_overdrive = partial(
            wall_overdrive, settings.controller, settings.friction, settings.part_density
        )
        compiled = compile_problem(problem)
        self.angles = compiled.frame
        self.checker = compiled.checker
        self._order = {spec.name: i for i, spec in enumerate(problem.objects)}
        self._block = {spec.name: self._is_block(spec) for spec in problem.objects}

    # -- what the model applies to ------------------------------------------------------------
    def _is_block(self, spec) -> bool:
        if spec.kind not in (ObjectKind.PART, ObjectKind.FIXTURE) or spec.shape.box is None:
            return False
        w, h = spec.shape.box
        d = self.block_size
        return abs(w - d) <= _SIZE_TOL and abs(h - d) <= _SIZE_TOL

    def _is_paddle(self, spec) -> bool:
        if spec.shape.box is None:
            return False
        a, b = sorted(spec.shape.box, reverse=True)
        length, thickness = self.paddle_size
        return abs(a - length) <= _SIZE_TOL and abs(b - thickness) <= _SIZE_TOL

    def allowance(self, depth: int) -> float:
        """Contact-slop allowance (inches) beyond ``x_max`` for an object at ``depth``:
        measured per depth in the training data, extrapolated linearly beyond it."""
        if depth in self._allowance:
            return self._allowance[depth]
        return depth * self._allowance_rate

    # -- beliefs ------------------------------------------------------------------------------
    def _interval(self, name: str, center: Pose, half: HalfWidths) -> ObjectInterval:
        theta = wrap_angle(center[2], self.angles.reference[name], self.angles.period[name])
        return ObjectInterval(
            (_r(center[0]), _r(center[1]), _r(theta)),
            (_r(abs(half[0])), _r(abs(half[1])), _r(abs(half[2]))),
        )

    def _belief(self, objects: dict[str, ObjectInterval]) -> IntervalBelief:
        return IntervalBelief(tuple(sorted(objects.items(), key=lambda kv: self._order[kv[0]])))

    def initial_belief(self) -> IntervalBelief:
        return self._belief(
            {e.name: self._interval(e.name, e.pose, e.uncertainty) for e in self.problem.initial}
        )

    def apply(self, belief: IntervalBelief, action: Action) -> IntervalBelief | None:
        if isinstance(action, Push):
            self.pushes += 1
            return self._push(belief, action)
        objects = dict(belief.objects)
        if isinstance(action, Place):
            objects[action.obj] = self._interval(
                action.obj, action.pose, self.problem.uncertainty.place
            )
        elif isinstance(action, Pick):
            objects.pop(action.obj, None)
        else:
            raise TypeError(f"not an action: {action!r}")
        return self._belief(objects)

    def fallback_counts(self) -> tuple[int, int] | None:
        """``(fell back, pushes)``: the push transitions the simulated fallback answered and
        all those asked for; None where this controller has no fallback
        (:data:`FALLBACK_PARTICLES`)."""
        return None if self.fallback is None else (self.fallbacks, self.pushes)

    def _refuse(self, reason: str) -> None:
        self.reasons[reason] += 1
        return None

    def _fall_back(self, belief: IntervalBelief, push: Push, reason: str) -> IntervalBelief | None:
        """The belief after ``push``, which the model refused for ``reason``: from the
        simulated fallback (:mod:`arrange_up.transitions.fallback`) where this controller has
        one, else None with ``reason`` counted. A push the physics refuses too is counted
        under the physics' reason."""
        if self.fallback is None:
            return self._refuse(reason)
        self.fallback_reasons[reason] += 1
        before = self.fallback.simulations
        answer = self.fallback.push(belief, push)
        self.simulations += self.fallback.simulations - before
        if isinstance(answer, str):
            return self._refuse(answer)
        self.fallbacks += 1
        objects = dict(belief.objects)
        for name, interval in answer.items():
            objects[name] = self._interval(name, interval.center, interval.half)
        return self._belief(objects)

    # -- push ---------------------------------------------------------------------------------
    def _push(self, belief: IntervalBelief, push: Push) -> IntervalBelief | None:
        problem = self.problem
        frame, paddle = self._paddle(push)
        if frame is None or paddle is None:
            return self._fall_back(belief, push, "the push is not axis-aligned")
        d = self.block_size
        nodes = self._nodes_of(belief, frame)
        table = frame.table_box(problem.table.size)
        wall = table[2] if frame.wall_ahead in problem.table.walls else None
        obstacles = [frame.box_to(box) for box in self.checker.obstacle_boxes.values()]
        fence = self._fence_ahead(belief, frame, paddle, wall)
        spread = 0.0
        if fence is not None:
            name, face, spread = fence
            wall = face
            nodes = [node for node in nodes if node.name != name]
        structure = analyse_push(
            paddle, nodes, wall=wall, block_size=d, obstacles=obstacles, memo=self._memo
        )
        if fence is not None and structure.kind == "predict":
            fixture = dict(belief.objects)[fence[0]]
            box = frame.box_to(self.checker.shadow_box(fence[0], fixture.center, (0.0, 0.0, 0.0)))
            # each member's centre, with a quarter block to spare on either side, in front of
            # the fixture (the planner's fences cover as much: planning.fences.COVER)
            by = {node.name: node for node in nodes}
            if any(
                by[m.name].center[1] - 0.25 * d < box[1] or by[m.name].center[1] + 0.25 * d > box[3]
                for m in structure.members
            ):
                return self._fall_back(belief, push, FIXTURE_REFUSAL)
        if structure.kind == "unchanged":
            return belief
        if structure.kind == "none":
            return self._fall_back(belief, push, structure.reason)
        # The outcome depends on the push, the structure and its members' nodes (which the
        # memo's structure stands for), and on a fence's pose: remembered without a fence.
        key = (push, id(structure)) if fence is None else None
        known = self._outcomes.get(key) if key is not None else None
        if known is None:
            outcome = self._outcome(push, frame, paddle, structure, nodes, table, wall, spread)
            if key is not None:
                if len(self._outcomes) >= OUTCOME_CACHE:
                    self._outcomes.clear()
                self._outcomes[key] = (structure, outcome)  # the structure keeps its id
        else:
            outcome = known[1]
        refusal, updates, simulated = outcome
        self.simulations += simulated
        if refusal is not None:
            return self._fall_back(belief, push, refusal)
        objects = dict(belief.objects)
        objects.update(updates)
        return self._belief(objects)

    def _paddle(self, push: Push) -> tuple[CanonicalFrame | None, Paddle | None]:
        """The push's canonical frame and its paddle in that frame (None, None when the push
        is not axis-aligned); remembered per push, since a search offers the same pushes in
        many beliefs."""
        known = self._paddles.get(push)
        if known is not None:
            return known
        spec = self.problem.object(push.manipulator)
        px, py = spec.push_direction
        frame = CanonicalFrame.of_vector(*rotate((px, py), push.pose[2]))
        paddle = None
        if frame is not None:
            push_unc = self.problem.uncertainty.push
            xmin, ymin, xmax, ymax = spec.shape.extent
            along_y = abs(py) > abs(px)  # the push direction in the manipulator's own frame
            length, thickness = (
                (xmax - xmin, ymax - ymin) if along_y else (ymax - ymin, xmax - xmin)
            )
            paddle = Paddle(
                center=frame.pose_to(push.pose),
                half=frame.half_to(push_unc),
                box=frame.box_to(self.checker.shadow_box(push.manipulator, push.pose, push_unc)),
                length=length,
                thickness=thickness,
                travel=float(push.distance),
            )
        if len(self._paddles) >= OUTCOME_CACHE:
            self._paddles.clear()
        self._paddles[push] = (frame, paddle)
        return frame, paddle

    def _outcome(self, push, frame, paddle, structure, nodes, table, wall, spread) -> _Outcome:
        """What a predictable push ``structure`` does: ``(refusal, updates, simulated)``, the
        reason it has no prediction (None if it has one), the members' new intervals and the
        number of model predictions it took (counted even when refused afterwards)."""
        problem = self.problem
        d = self.block_size
        if not self._is_paddle(problem.object(push.manipulator)):
            return f"{push.manipulator!r} is not the paddle the model was trained on", {}, 0
        assert wall is not None
        if self._trained_wall_push == "planner" and not self._sent_as_trained(
            paddle, wall, structure.length
        ):
            return TRAINED_PUSH_REFUSAL, {}, 0
        by_name = {node.name: node for node in nodes}

        def neighbour(key):
            if key is ROBOT:
                return paddle.half, paddle.center[1], False
            node = by_name[key]
            return node.half, node.center[1], True

        rows, owner = [], []
        for k, member in enumerate(structure.members):
            if member.grazed:
                continue
            cur = by_name[member.name]
            for prev in member.prevs:
                p_half, p_v, p_obj = neighbour(prev)
                for nxt in member.nexts:
                    n_half, n_v = (None, None) if nxt is WALL else neighbour(nxt)[:2]
                    rows.append(
                        feature_row(p_half, p_v, p_obj, cur.half, cur.center[1], n_half, n_v)
                    )
                    owner.append(k)
        pred = self._predict(rows)
        if pred is None:
            return "a pushed object's belief is outside the model's training domain", {}, 0
        simulated = len(rows)
        owner_arr = np.asarray(owner, dtype=int)
        low_wall, high_wall = frame.side_walls
        v_min = table[1] + 0.5 * d if low_wall in problem.table.walls else -math.inf
        v_max = table[3] - 0.5 * d if high_wall in problem.table.walls else math.inf
        updates: dict[str, ObjectInterval] = {}
        for k, member in enumerate(structure.members):
            cur = by_name[member.name]
            if member.grazed:
                # Left alone or touched by a corner sliding past: it stays where it may be,
                # may be nudged forward up to x_max (plus slop) and sideways by the overlap,
                # at most by the allowance measured in simulation.
                x_max = wall - (member.depth - 0.5) * d
                u_low = cur.center[0] - cur.half[0]
                u_high = max(
                    cur.center[0] + cur.half[0], x_max + spread + self.allowance(member.depth)
                )
                aside = min(member.graze, self.graze_allowance)
                v_low = max(cur.center[1] - cur.half[1] - aside, v_min)
                v_high = min(cur.center[1] + cur.half[1] + aside, v_max)
                canonical = (0.5 * (u_low + u_high), 0.5 * (v_low + v_high), cur.center[2])
                half = frame.half_from(
                    (0.5 * (u_high - u_low), 0.5 * (v_high - v_low), cur.half[2])
                )
                updates[member.name] = self._interval(member.name, frame.pose_from(canonical), half)
                continue
            dx, dy, dth, slip = pred[owner_arr == k].max(axis=0)[:4]
            if slip > BUCKLE_LIMIT:
                return "the model predicts that the train may buckle", {}, simulated
            x_max = wall - (member.depth - 0.5) * d
            u_low = x_max - spread - dx
            u_high = x_max + spread + max(slip, self.allowance(member.depth))
            v = cur.center[1]
            v_low, v_high = max(v - dy, v_min), min(v + dy, v_max)
            if v_low > v_high:
                return f"{member.name!r} would end outside the table", {}, simulated
            canonical = (0.5 * (u_low + u_high), 0.5 * (v_low + v_high), 0.0)
            half = frame.half_from(
                (0.5 * (u_high - u_low), 0.5 * (v_high - v_low), math.radians(dth))
            )
            updates[member.name] = self._interval(member.name, frame.pose_from(canonical), half)
        return None, updates, simulated

    def _nodes_of(self, belief: IntervalBelief, frame: CanonicalFrame) -> list[Node]:
        """The contact graph's nodes of ``belief``'s objects in ``frame``; the last belief's
        are kept per direction, since a search evaluates one belief's pushes in a row."""
        last = self._last_nodes.get(frame.direction)
        if last is not None and last[0] is belief:
            return last[1]
        nodes = [self._node(frame, name, iv) for name, iv in belief.objects]
        self._last_nodes[frame.direction] = (belief, nodes)
        return nodes

    def _node(self, frame: CanonicalFrame, name: str, interval: ObjectInterval) -> Node:
        """The contact graph's node of ``name`` at ``interval`` in ``frame``; remembered (up to
        :data:`NODE_CACHE` of them), since the same objects' beliefs recur in many beliefs."""
        key = (frame.direction, name, interval)
        node = self._nodes.get(key)
        if node is None:
            center = frame.pose_to(interval.center)
            # The model was trained on square blocks with centre angle 0 (mod 90 degrees).
            aligned = abs(wrap_angle(center[2], 0.0, 0.5 * math.pi)) <= 1e-6
            box = self.checker.shadow_box(name, interval.center, interval.half)
            node = Node(
                name,
                center,
                frame.half_to(interval.half),
                frame.box_to(box),
                block=self._block.get(name, False) and aligned,
            )
            if len(self._nodes) >= NODE_CACHE:
                self._nodes.clear()
            self._nodes[key] = node
        return node

    def _predict(self, rows: list[list[float]]) -> np.ndarray | None:
        """The model's ``(dx, dy, dth, slip)`` (clipped at 0) per feature row, or None when a
        row lies outside the training domain.

        Each distinct row is judged and predicted once per search and then remembered
        (:data:`PREDICTION_CACHE` rows): a search meets the same rows again and again, since
        the same objects' beliefs recur in many beliefs. A row's prediction does not depend on
        the rows predicted beside it, so the answers are those of a batch of all rows.
        """
        known = self._predictions
        if len(known) > PREDICTION_CACHE:
            known.clear()
        keys = [tuple(row) for row in rows]
        new = list(dict.fromkeys(key for key in keys if key not in known))
        if new:
            X = np.asarray(new, dtype=float).reshape(-1, 12)
            inside = self.domain.contains(X)
            pred = np.zeros((len(new), 4))
            if inside.any():
                pred[inside] = np.maximum(self.model.predict_rows(X[inside]), 0.0)
            for key, ok, row in zip(new, inside, pred, strict=True):
                known[key] = row if ok else None
        found = [known[key] for key in keys]
        if any(row is None for row in found):
            return None
        return np.asarray(found).reshape(-1, 4)

    def _sent_as_trained(self, paddle: Paddle, wall: float, length: int) -> bool:
        """Whether the push sends the paddle's front where the training pushes of a model
        trained with ``wall_push="planner"`` sent it (:mod:`arrange_up.cbst.data`): past the
        compressed train of ``length`` blocks by the training settings' ``wall_overdrive`` for
        the paddle's pose uncertainty along the push (at the wall when that is None), within
        :data:`TRAINED_PUSH_TOLERANCE`."""
        d = self.block_size
        over = self._trained_overdrive(length * d * d, paddle.half[0])
        target = wall_push_front(wall, length * d, over)
        front = paddle.center[0] + 0.5 * paddle.thickness + paddle.travel
        return abs(front - target) <= TRAINED_PUSH_TOLERANCE

    def _fence_ahead(self, belief, frame, paddle, wall) -> tuple[str, float, float] | None:
        """The fixture on the table that stands in for the wall ahead (module docstring):
        ``(name, nominal face, face spread)`` in the canonical frame, or None."""
        best = None
        reach = paddle.reach_box
        for spec in self.problem.fixtures:
            interval = belief.get(spec.name)
            if interval is None:
                continue
            nominal = frame.box_to(self.checker.shadow_box(spec.name, interval.center, (0.0,) * 3))
            shadow = frame.box_to(
                self.checker.shadow_box(spec.name, interval.center, interval.half)
            )
            ahead = shadow[0] >= paddle.box[2] - 1e-9
            across = min(shadow[3], reach[3]) > max(shadow[1], reach[1])
            nearer = wall is None or nominal[0] < wall
            if ahead and across and nearer and (best is None or nominal[0] < best[1]):
                best = (spec.name, nominal[0], nominal[0] - shadow[0])
        return best

    def close(self) -> None:
        """Nothing to release."""
