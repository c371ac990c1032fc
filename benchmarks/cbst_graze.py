"""How CBST's grazing rule holds up in simulation, and what it and the place grid cost planning.

Usage::

    python benchmarks/cbst_graze.py measure [--problems blocks-3] [--controller servo]
        [--cases 40] [--states 40] [--seed 0]
    python benchmarks/cbst_graze.py scenes [--scenes 300] [--states 50] [--controller servo]
    python benchmarks/cbst_graze.py plan [--problems blocks-3,blocks-4,blocks-7]
        [--graze 1,0] [--allowance inf] [--farther-places] [--flush-within 0.07]
        [--controller servo]
        [--evaluate 1000] [--workers 2]

A *grazed* block (docs/cbst.md, "The contact graph") is one a push may touch only with the
corner of a neighbouring row sliding past, and is already flush. CBST keeps its box, extends it
forward to where it would be flush, and widens it across the push on both sides by the overlap
of the grazer's shadow box with its own (``contact_graph._shadow_overlap``), the most a corner
sliding straight past can push it aside, but by no more than the controller's grazing
allowance (``arrange_up.transitions.cbst.GRAZE_ALLOWANCE``, measured by ``scenes``). Its angle
box is kept.

``measure`` plans each problem with the shipped model of its controller
(``plan(..., semantics="cbst")``, as ``arrange-up plan PROBLEM --semantics cbst`` does) and
records every push the search predicted that has a grazed block. It draws ``--cases`` of them
(seeded), simulates each from ``--states`` states drawn uniformly from the belief before the
push (draws whose objects overlap are rejected, up to 50 times ``--states``; a belief whose
blocks are flush yields fewer), with the push's noise, and prints for every grazed block: the
overlap bound, how far it moved across the push, how far it ended beyond its box before the push
across the push, how far it turned, and how far it ended beyond the box CBST predicted (along,
across, angle). A summary line counts the blocks that ended beyond their predicted box by more
than the physics' contact slop (0.005 in, 0.5 degrees, as tests/transitions/test_cbst_semantics.py
allows).

``scenes`` asks the same of generated scenes (:func:`graze_scene`): a training example's train
and a neighbouring block against the wall beside it, predicted by the shipped model of the
controller (``--controller``) and simulated from ``--states`` states of the belief. It prints,
for the neighbour grazed, pushed (a member of the train, predicted by PREDICT) or left alone,
and for its position spread along the push up to each of ``--spreads``, how many scenes ended
with it beyond its predicted box by more than the slop, and by how much.

``plan`` plans each problem (300 s each) under variants, one row each:

* ``--graze S``: the overlap bound scaled by ``S`` (1 is CBST's rule; 0 leaves a grazed block's
  box unwidened across the push, a probe of what the widening costs);
* ``--allowance A``: the most a grazed block is widened across the push (CBST's
  ``GRAZE_ALLOWANCE``, measured by ``scenes``, per controller); ``inf`` is the overlap alone;
* ``--farther-places``: where no place of the 3 x 3 grid about a part's target is clear, also
  the places 2, 3 and 4 grid steps out along each of its offsets (the grid stops one step from
  the target, and a neighbour pressed into a corner under the compliant controller, its angle
  uncertain by several degrees, can block every step of it); otherwise the generator's places;
* ``--flush-within T``: a grazed block must also lie within ``T`` inches of flush in every
  state of its box (CBST's rule asks only that its range reach flush), else the push has no
  prediction: the rule the generated scenes suggest would keep grazed blocks in their boxes.

The variants patch this process only (the library's CBST and action generator are unchanged).
``--evaluate N`` scores every plan found on N rollouts (seed 0).
"""

from __future__ import annotations

import argparse
import contextlib
import math
import random
import statistics
from collections.abc import Iterator
from dataclasses import dataclass, replace

import numpy as np
from cbst_compliant_plans import result_line  # this folder's: the scripts run from it

from arrange_up.belief.states import IntervalBelief, ObjectInterval
from arrange_up.cbst import contact_graph
from arrange_up.cbst.data import (
    COMPLIANT,
    SERVO,
    GenerationSettings,
    _draw_config,
    _sample_state,
    _scene,
    _square_reach,
    _squares_overlap,
)
from arrange_up.cbst.frame import CanonicalFrame
from arrange_up.geometry.collision import CollisionChecker
from arrange_up.io.domains import load
from arrange_up.model.problem import ArrangementProblem, Controller, ControllerKind, Uncertainty
from arrange_up.model.world import Place, Push, WorldState, draw_noise
from arrange_up.physics.simulation import simulate
from arrange_up.planning.generators import places as place_generator
from arrange_up.planning.generators.common import clean_pose
from arrange_up.planning.planner import plan
from arrange_up.transitions.cbst import GRAZE_ALLOWANCE, CBSTSemantics

#: The physics' contact slop: an outcome this far beyond a predicted box is inside it.
SLOP = (0.005, 0.005, math.radians(0.5))
#: Grid steps out along each offset that ``--farther-places`` adds.
FARTHER = (2, 3, 4)
#: Rejected draws allowed per state wanted.
DRAWS_PER_STATE = 50


@dataclass(frozen=True)
class GrazeCase:
    """A push the search predicted with grazed blocks: the belief before it, the push, its
    canonical frame, each grazed block's overlap bound, and the predicted boxes."""

    belief: IntervalBelief
    push: Push
    frame: CanonicalFrame
    grazed: tuple[tuple[str, float], ...]
    predicted: dict[str, ObjectInterval]


@contextlib.contextmanager
def recording(cases: list[GrazeCase]) -> Iterator[None]:
    """Record into ``cases`` every push a CBST semantics predicts with grazed blocks (the
    first time it meets the push's structure; against a table wall, not a fixture)."""
    original_push, original_outcome = CBSTSemantics._push, CBSTSemantics._outcome
    before: list[IntervalBelief] = []

    def push(self, belief, action):
        before.append(belief)
        try:
            return original_push(self, belief, action)
        finally:
            before.pop()

    def outcome(self, action, frame, paddle, structure, nodes, table, wall, spread):
        result = original_outcome(
            self, action, frame, paddle, structure, nodes, table, wall, spread
        )
        grazed = tuple((m.name, m.graze) for m in structure.members if m.grazed)
        if result[0] is None and grazed and spread == 0.0:
            cases.append(GrazeCase(before[-1], action, frame, grazed, result[1]))
        return result

    CBSTSemantics._push, CBSTSemantics._outcome = push, outcome
    try:
        yield
    finally:
        CBSTSemantics._push, CBSTSemantics._outcome = original_push, original_outcome


@contextlib.contextmanager
def graze_scale(scale: float) -> Iterator[None]:
    """CBST's overlap bound of a grazed block scaled by ``scale`` in this process."""
    original = contact_graph._shadow_overlap
    if scale != 1.0:
        contact_graph._shadow_overlap = lambda a, b: scale * original(a, b)
    try:
        yield
    finally:
        contact_graph._shadow_overlap = original


@contextlib.contextmanager
def graze_allowance(allowance: float | None) -> Iterator[None]:
    """Every controller's :data:`~arrange_up.transitions.cbst.GRAZE_ALLOWANCE` set to
    ``allowance`` inches in this process (``inf``: the overlap alone, the rule before the
    allowance; None: as shipped)."""
    original = dict(GRAZE_ALLOWANCE)
    if allowance is not None:
        GRAZE_ALLOWANCE.update(dict.fromkeys(GRAZE_ALLOWANCE, allowance))
    try:
        yield
    finally:
        GRAZE_ALLOWANCE.update(original)


@contextlib.contextmanager
def flush_within(spread: float | None) -> Iterator[None]:
    """A grazed block must also lie, in every state of its box, within ``spread`` inches of
    where it would be flush (None: CBST's rule, its range need only reach there)."""
    original = contact_graph._flush
    if spread is not None:
        contact_graph._flush = lambda node, x_max: (
            original(node, x_max) and node.center[0] - node.half[0] >= x_max - spread
        )
    try:
        yield
    finally:
        contact_graph._flush = original


@contextlib.contextmanager
def farther_places(enabled: bool) -> Iterator[None]:
    """The action generator's places, plus (where a part has none) places further out."""
    original = place_generator.PlaceGenerator.places

    def places(self, belief, only=None):
        found = original(self, belief, only)
        placed = {a.obj for a in found}
        on_table = [(n, iv.center, iv.half) for n, iv in belief.objects]
        boxes = [self.checker.shadow_box(*shadow) for shadow in on_table]
        for spec in self.problem.parts:
            name = spec.name
            if name in belief or name in placed or (only is not None and name != only):
                continue
            for target in self.targets.place_targets(name, belief):
                count = len(found)
                for dx, dy in self.offsets[name]:
                    if (dx, dy) == (0.0, 0.0):
                        continue
                    for k in FARTHER:
                        for theta in self._place_angles(target):
                            pose = (target[0] + k * dx, target[1] + k * dy, theta)
                            if self._place_ok(name, pose, self.place_unc, on_table, boxes):
                                found.append(Place(name, clean_pose(pose)))
                if len(found) > count:
                    break
        return found

    if enabled:
        place_generator.PlaceGenerator.places = places
    try:
        yield
    finally:
        place_generator.PlaceGenerator.places = original


def _problem(name: str, controller: str | None) -> ArrangementProblem:
    problem = load(name)
    if controller is not None:
        problem = replace(problem, controller=Controller(kind=ControllerKind(controller)))
    return problem


def _outcomes(problem, case: GrazeCase, states: int, rng) -> list[tuple[dict, dict]]:
    """Up to ``states`` (before, after) pose maps of the case's push from uniform draws."""
    checker, out = CollisionChecker(problem), []
    for _ in range(states * DRAWS_PER_STATE):
        if len(out) == states:
            break
        poses = {
            name: tuple(iv.center[i] + rng.uniform(-1, 1) * iv.half[i] for i in range(3))
            for name, iv in case.belief.objects
        }
        state = WorldState.from_mapping(problem, poses)
        if checker.state_collides(state):
            continue
        result = simulate(problem, state, case.push, draw_noise(problem, case.push, rng))
        if result.ok:
            out.append((poses, result.state.as_dict()))
    return out


def _turn(angle: float, reference: float) -> float:
    """``angle - reference`` wrapped into a square block's period (±45 degrees)."""
    return (angle - reference + math.pi / 4) % (math.pi / 2) - math.pi / 4


def measure(args: argparse.Namespace) -> None:
    """The ``measure`` command (see the module docstring)."""
    for name in args.problems.split(","):
        problem = _problem(name, args.controller)
        cases: list[GrazeCase] = []
        with recording(cases):
            result = plan(problem, semantics="cbst", workers=1, timeout=300)
        print(
            f"{name} ({problem.controller.kind.value}): {result.status}, "
            f"{result.stats['expanded']} nodes; {len(cases)} pushes with grazed blocks",
            flush=True,
        )
        drawn = random.Random(args.seed).sample(cases, min(args.cases, len(cases)))
        rng = np.random.default_rng(args.seed)
        bounds, moved, beyond = [], [], []
        for case in drawn:
            outcomes = _outcomes(problem, case, args.states, rng)
            for block, bound in case.grazed:
                prior, predicted = case.belief.get(block), case.predicted[block]
                lo, hi = sorted(case.frame.pose_to(p)[1] for p in (prior.low, prior.high))
                across = outside = turn = 0.0
                excess = [0.0, 0.0, 0.0]
                for start, end in outcomes:
                    v0, v1 = case.frame.pose_to(start[block])[1], case.frame.pose_to(end[block])[1]
                    across = max(across, abs(v1 - v0))
                    outside = max(outside, lo - v1, v1 - hi)
                    turn = max(turn, abs(_turn(end[block][2], start[block][2])))
                    pose = (
                        *end[block][:2],
                        predicted.center[2] + _turn(end[block][2], predicted.center[2]),
                    )
                    for i in range(3):
                        excess[i] = max(
                            excess[i], predicted.low[i] - pose[i], pose[i] - predicted.high[i]
                        )
                if not outcomes:
                    continue
                bounds.append(bound)
                moved.append(outside)
                beyond.append(excess)
                print(
                    f"  {block}: bound {bound:.3f} in; moved across up to {across:.4f} in, "
                    f"{outside:.4f} in beyond its box; turned up to {math.degrees(turn):.2f} deg; "
                    f"beyond the predicted box x {excess[0]:.4f} in, y {excess[1]:.4f} in, "
                    f"angle {math.degrees(excess[2]):.2f} deg ({len(outcomes)} states, prior "
                    f"half-widths along the push {case.frame.half_to(prior.half)[0]:.3f} in, "
                    f"angle {math.degrees(prior.half[2]):.1f} deg)",
                    flush=True,
                )
        if not bounds:
            print(f"{name}: no grazed block could be simulated")
            continue
        out = sum(1 for e in beyond if any(e[i] > SLOP[i] for i in range(3)))
        print(
            f"{name}: {len(bounds)} grazed blocks simulated; overlap bound median "
            f"{statistics.median(bounds):.3f} in; beyond the box before the push across it: "
            f"max {max(moved):.4f} in; beyond the predicted box by more than the slop: {out}, "
            f"by up to {max(e[0] for e in beyond):.4f} in along x, "
            f"{max(e[1] for e in beyond):.4f} in along y, "
            f"{math.degrees(max(e[2] for e in beyond)):.2f} deg",
            flush=True,
        )


def plan_variants(args: argparse.Namespace) -> None:
    """The ``plan`` command (see the module docstring)."""
    for scale in (float(s) for s in args.graze.split(",")):
        for name in args.problems.split(","):
            problem = _problem(name, args.controller)
            with (
                graze_scale(scale),
                graze_allowance(args.allowance),
                farther_places(args.farther_places),
                flush_within(args.flush_within),
            ):
                result = plan(problem, semantics="cbst", workers=1, timeout=300)
            variant = f"graze x{scale:g}"
            if args.farther_places:
                variant += ", farther places"
            if args.allowance is not None:
                variant += f", allowance {args.allowance:g} in"
            if args.flush_within is not None:
                variant += f", flush within {args.flush_within:g} in"
            print(result_line(f"{variant} {name}", problem, result, args), flush=True)


def graze_scene(index: int, seed: int, settings: GenerationSettings):
    """Scene ``index`` of ``seed``: the problem (the training scene, the paddle's pose
    uncertainty as its push uncertainty), the belief and the push, or None when no neighbour
    offset gives a possible contact. A training example's train of 1 or 2 blocks
    (:func:`arrange_up.cbst.data._draw_config`, the settings' push to the wall) and a
    neighbour block ``N`` against the wall beside it: its half-widths up to half the training
    domain's along and across the push and up to all of its angle, its position range reaching
    within ``FLUSH_TOLERANCE`` of the wall, on either side of a train block drawn at random,
    offset across so that their shadows overlap but their contact is not certain."""
    rng = np.random.default_rng([seed, index, 0x67A2E])
    s, d = settings, settings.block_size
    h, bh = 0.5 * d, s.domain.block_half
    n = int(rng.integers(1, 3))
    cfg = _draw_config(rng, n, s)
    grazer = int(rng.integers(0, n))
    half = (
        float(rng.uniform(0.0, 0.5 * bh[0])),
        float(rng.uniform(0.0, 0.5 * bh[1])),
        math.radians(float(rng.uniform(0.0, bh[2]))),
    )
    u = cfg.wall - h - half[0] - float(rng.uniform(0.0, contact_graph.FLUSH_TOLERANCE))
    gv, (_, ghv, ght) = cfg.centers[grazer][1], cfg.halves[grazer]
    low = max(0.0, d - s.min_overlap - ghv - half[1])  # nearer: a certain contact
    high = h * (_square_reach(ght) + _square_reach(half[2])) + ghv + half[1]  # shadows apart
    if high <= low:
        return None
    v = gv + (1 if rng.random() < 0.5 else -1) * float(rng.uniform(low, high))
    names = [f"b{j}" for j in range(n + 1)]
    centers = [(*c, 0.0) for c in cfg.centers] + [(u, v, 0.0)]
    belief = IntervalBelief(
        tuple(
            (name, ObjectInterval(center, hw))
            for name, center, hw in zip(names, centers, [*cfg.halves, half], strict=True)
        )
    )
    uncertainty = Uncertainty(
        push=cfg.paddle_half,
        friction=s.friction,
        part_density=s.part_density,
        manipulator_density=s.manipulator_density,
    )
    problem = replace(_scene(s), uncertainty=uncertainty)
    return problem, belief, Push("paddle", cfg.paddle_pose, cfg.distance), cfg, rng


def _scene_states(problem, belief, cfg, rng, states: int):
    """Up to ``states`` pose maps drawn uniformly from the scene's belief (rejecting overlaps
    and poses through the wall)."""
    h = 0.5 * problem.objects[0].shape.box[0]
    names = belief.names()
    out = []
    for _ in range(states * DRAWS_PER_STATE):
        if len(out) == states:
            break
        train = _sample_state(rng, cfg, h, 1)
        if train is None:
            continue
        iv = belief.get(names[-1])
        pose = tuple(iv.center[i] + float(rng.uniform(-1, 1)) * iv.half[i] for i in range(3))
        if pose[0] + h * _square_reach(pose[2]) > cfg.wall:
            continue
        if any(_squares_overlap(p, pose, h) for p in train):
            continue
        out.append(dict(zip(names, [*train, pose], strict=True)))
    return out


def scenes(args: argparse.Namespace) -> None:
    """The ``scenes`` command (see the module docstring)."""
    controller = SERVO if args.controller == "servo" else COMPLIANT
    wall_push = "uniform" if args.controller == "servo" else "planner"
    settings = GenerationSettings(controller=controller, wall_push=wall_push)
    refused: dict[str, int] = {}
    # kind, spread along the push, excess beyond the predicted box, beyond the prior box across
    rows: list[tuple[str, float, list[float], float]] = []
    for index in range(args.scenes):
        drawn = graze_scene(index, args.seed, settings)
        if drawn is None:
            refused["no offset"] = refused.get("no offset", 0) + 1
            continue
        problem, belief, push, cfg, rng = drawn
        semantics = CBSTSemantics(problem, model=args.controller or "compliant")
        cases: list[GrazeCase] = []
        with recording(cases):
            post = semantics.apply(belief, push)
        neighbour = belief.names()[-1]
        if post is None:
            for reason in semantics.reasons:
                refused[reason] = refused.get(reason, 0) + 1
            continue
        grazed = dict(cases[0].grazed) if cases else {}
        moved = post.get(neighbour) != belief.get(neighbour)
        kind = "grazed" if neighbour in grazed else ("pushed" if moved else "left alone")
        predicted, prior = post.get(neighbour), belief.get(neighbour)
        excess = [0.0, 0.0, 0.0]
        aside = 0.0  # how far the neighbour ended beyond its box before the push, across it
        starts = _scene_states(problem, belief, cfg, rng, args.states)
        for start in starts:
            state = WorldState.from_mapping(problem, start)
            result = simulate(problem, state, push, draw_noise(problem, push, rng))
            if not result.ok:
                continue
            end = result.state.as_dict()[neighbour]
            pose = (*end[:2], predicted.center[2] + _turn(end[2], predicted.center[2]))
            for i in range(3):
                excess[i] = max(excess[i], predicted.low[i] - pose[i], pose[i] - predicted.high[i])
            aside = max(aside, prior.low[1] - end[1], end[1] - prior.high[1])
        if not starts:
            continue
        rows.append((kind, 2.0 * prior.half[0], excess, aside))
    print(
        f"{args.controller or 'compliant'}: {args.scenes} scenes; predicted {len(rows)}; "
        "not predicted: "
        + ", ".join(f"{k} {v}" for k, v in sorted(refused.items(), key=lambda kv: -kv[1])),
        flush=True,
    )
    aside = np.array([r[3] for r in rows if r[0] == "grazed"])
    if aside.size:
        p95, p99 = np.percentile(aside, [95, 99])
        print(
            f"  grazed neighbours, how far beyond their box before the push they ended across "
            f"it: 95th percentile {p95:.3f} in, 99th {p99:.3f} in, largest {aside.max():.3f} in "
            f"({aside.size} scenes; the grazing allowance, docs/cbst.md)",
            flush=True,
        )
    for kind in ("grazed", "pushed", "left alone"):
        for limit in [*args.spreads, math.inf]:
            some = [r for r in rows if r[0] == kind and r[1] <= limit + 1e-9]
            out = [r for r in some if any(r[2][i] > SLOP[i] for i in range(3))]
            if not some:
                continue
            spread = "any" if math.isinf(limit) else f"up to {limit:g} in"
            print(
                f"  neighbour {kind}, its position spread along the push {spread}: {len(some)}; "
                f"{len(out)} end beyond the predicted box by more than the slop, by up to "
                f"{max(r[2][0] for r in some):.3f} in along x, {max(r[2][1] for r in some):.3f} "
                f"in along y, {math.degrees(max(r[2][2] for r in some)):.2f} deg",
                flush=True,
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    commands = parser.add_subparsers(dest="command", required=True)
    m = commands.add_parser("measure", help="simulate the grazes a CBST search predicted")
    p = commands.add_parser("plan", help="plan with the grazing bound scaled, places further out")
    g = commands.add_parser("scenes", help="simulate grazes in generated scenes")
    g.add_argument(
        "--scenes",
        type=int,
        default=300,
        help="scenes drawn (default: %(default)s)",
    )
    for sub, states, drawn in ((g, 50, "scenes"), (m, 40, "pushes")):
        sub.add_argument(
            "--states",
            type=int,
            default=states,
            help=f"states drawn from the belief before each of the {drawn} and simulated "
            "(default: %(default)s)",
        )
        sub.add_argument(
            "--seed",
            type=int,
            default=0,
            help=f"seed of the draws of {drawn}, states and noise (default: %(default)s)",
        )
    g.add_argument(
        "--controller",
        choices=("compliant", "servo"),
        default=None,
        help="the controller of the rollouts and the shipped model predicting them "
        "(default: compliant)",
    )
    g.add_argument(
        "--spreads",
        type=lambda text: [float(v) for v in text.split(",")],
        default=[0.02, 0.05, 0.1, 0.2],
        metavar="INCHES",
        help="comma-separated limits on the neighbour's position spread along the push, one "
        "summary line each (default: 0.02,0.05,0.1,0.2)",
    )
    for sub, problems in ((m, "blocks-3"), (p, "blocks-3,blocks-4,blocks-7")):
        sub.add_argument(
            "--problems",
            default=problems,
            help="comma-separated shipped problems (default: %(default)s)",
        )
        sub.add_argument(
            "--controller",
            choices=("compliant", "servo"),
            default=None,
            help="drive the problems by this controller at its defaults, planning with its "
            "shipped model (default: each problem's own)",
        )
    m.add_argument(
        "--cases",
        type=int,
        default=40,
        help="pushes with grazed blocks drawn from those the search predicted (default: "
        "%(default)s)",
    )
    p.add_argument(
        "--graze",
        default="1,0",
        metavar="SCALES",
        help="comma-separated factors on the grazing bound, one row per problem each; 1 is "
        "CBST's rule, 0 an unsound probe (default: %(default)s)",
    )
    p.add_argument(
        "--farther-places",
        action="store_true",
        help="where no grid place about a part's target is clear, also offer places 2-4 grid "
        "steps out",
    )
    p.add_argument(
        "--allowance",
        type=float,
        default=None,
        metavar="INCHES",
        help="the most a grazed block is widened across the push, for every controller; inf "
        "for the grazer's overlap alone (default: CBST's GRAZE_ALLOWANCE of the controller)",
    )
    p.add_argument(
        "--flush-within",
        type=float,
        default=None,
        metavar="INCHES",
        help="a grazed block must also lie within this distance of flush in every state of "
        "its box (default: CBST's rule, its range need only reach flush)",
    )
    p.add_argument(
        "--evaluate",
        type=int,
        default=0,
        metavar="N",
        help="rollouts (seed 0) scoring every plan found (default: %(default)s, none)",
    )
    p.add_argument(
        "--workers",
        type=int,
        default=1,
        help="processes evaluating the plans (default: %(default)s)",
    )
    args = parser.parse_args()
    if args.command == "measure":
        measure(args)
    elif args.command == "scenes":
        scenes(args)
    else:
        plan_variants(args)


if __name__ == "__main__":
    main()
