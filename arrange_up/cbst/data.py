"""Training data for PREDICT (thesis §3.2), generated with arrange-up's own physics.

One *example* is a random interval belief of 1 to 3 blocks in a row between the paddle and a
wall, pushed K times (K "rollouts"); it yields one training row per block (features and
targets of :mod:`arrange_up.cbst.features`). Everything is in the canonical frame: the push
goes toward ``+x`` and the wall is the table's right wall.

How an example is drawn (``GenerationSettings`` holds every number):

* ``n`` blocks, uniformly 1, 2 or 3; 1-inch square blocks and the 2.5 x 0.15 in paddle of the
  block-world domains.
* Each block's belief: half-widths ``dx, dy`` uniform in ``[0, 0.4]`` in, ``dθ`` uniform in
  ``[0, 15]`` degrees (the thesis's ranges), centre angle 0.
* Centres across the push: the first block at the table's middle; each next one offset
  uniformly within the range that keeps the contact *certain* (the two blocks' spans across
  the push overlap by at least ``MIN_OVERLAP`` in every state: the same rule the contact graph
  uses to accept a train; ``dy`` is redrawn in the rare case no offset qualifies).
* Along the push: the last block ``0 .. 1`` in from the wall; each gap between consecutive
  position ranges from ``d - 2 min(dx)`` (tight, as after a previous push against a wall) to
  ``d + 0.6`` in.
* The paddle: pose uncertainty uniform in ``[0, 0.1]`` in, ``[0, 0.1]`` in, ``[0, 5]`` degrees;
  offset across the push from the first block uniform within ``±1.5`` in (the action
  generator centres the paddle within 1.15 in of the part it targets; other blocks it hits
  may be further out), narrowed so its contact is certain (``MIN_OVERLAP_PADDLE``); its
  shadow ``0.02 .. 0.5`` in
  behind the first block's shadow. The commanded reference puts the paddle's front, with
  ``wall_push="uniform"`` (the default, and the data of the shipped servo model),
  uniformly between ``PUSH_MARGIN`` beyond the fully compressed train and the wall; with
  ``"wall"`` at the wall (the planner's push to a wall without ``compressed_wall_pushes``,
  :mod:`arrange_up.planning.actions`); with ``"planner"`` where CBST's push to the wall
  sends it under the settings' controller (:func:`arrange_up.physics.stall.wall_overdrive`
  beyond the compressed train, for the train's blocks, the friction and density ranges below
  and the paddle's pose uncertainty along the push; the wall itself under the servo), so
  that the model predicts the pushes CBST plans with. The uniform draw is made in every
  case, so the three settings draw the same scenes and rollouts.
* Each rollout draws a state uniformly from the belief (rejecting states where blocks overlap
  each other or the wall: the thesis's non-collision constraint), the paddle's pose noise,
  the friction coefficient uniformly in ``[0.25, 0.55]`` and the part and paddle densities
  from the block domains' ranges, and simulates the push with
  :func:`arrange_up.physics.simulation.simulate`.
* Targets over the rollouts that came to rest (the others are counted; an example with fewer
  than 90 % of its rollouts at rest is kept in the file but not trained on): ``dx``, ``dy``,
  ``dθ`` and ``slip`` as defined in :mod:`.features`, each the settings' ``quantile`` of the
  rollouts (1.0: their largest). The largest overshoot of ``x_max`` is recorded too, to
  check the structural assumption that the train ends flush against the wall.
* With ``outcomes=True`` (the fresh test sets of :func:`arrange_up.cbst.model.train_cbst`)
  a record also keeps, per block, every rollout's four deviations (``x_max - u``,
  ``|v - v_c|``, ``|θ|`` in degrees, ``u - x_max``), from which a model's *coverage* is
  measured: the share of rollouts ending inside its predicted box.

Reproducibility: example ``i`` is a function of ``(seed, i, K, settings)`` only (its generator
is seeded with ``[seed, i]``), so the data set is the same for any worker count or order.

Resumable: examples are appended, one JSON object per line, to a ``.jsonl`` file as they
finish; a rerun skips the indices already there (a torn last line is dropped). Each line
records the seed, K and a digest of the settings, and a file generated with other settings
is refused rather than mixed.

Parallel: examples are computed through the project's runners (:mod:`arrange_up.parallel`:
local loky processes or a Dask cluster), in chunks, and written by the calling process as
they come back (in completion order; the file is read back in index order).
"""

from __future__ import annotations

import hashlib
import json
import math
import os
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import asdict, dataclass, field
from functools import cache, partial
from pathlib import Path
from typing import Any

import numpy as np

from arrange_up.cbst.contact_graph import MIN_OVERLAP, MIN_OVERLAP_PADDLE, PUSH_MARGIN
from arrange_up.cbst.features import Domain, feature_row
from arrange_up.geometry.shapes import shadow_box
from arrange_up.io.files import recorded_lines
from arrange_up.model.problem import (
    ArrangementProblem,
    Controller,
    ControllerKind,
    Goal,
    ObjectKind,
    ObjectSpec,
    Shape,
    Table,
)
from arrange_up.model.world import ActionNoise, Push, WorldState
from arrange_up.parallel import auto_chunksize, get_runner
from arrange_up.physics.simulation import simulate
from arrange_up.physics.stall import wall_overdrive, wall_push_front

__all__ = [
    "COMPLIANT",
    "DATA_FORMAT",
    "Dataset",
    "GenerationSettings",
    "TrainingProgress",
    "SHIPPED_WALL_PUSH",
    "WALL_PUSHES",
    "generate_dataset",
    "generate_example",
    "load_dataset",
]

DATA_FORMAT = "arrange-up-cbst-data/1"

TrainingProgress = Callable[[str, int, int], None]
"""``progress(stage, done, total)``."""

#: Paddle angle that pushes toward +x (the paddle pushes along its frame's +y).
EAST = -0.5 * math.pi


#: The compliant controller with every gain at its documented default: what the shipped
#: compliant model is trained in (named explicitly, not the problems' default controller, so a
#: change of that default does not change the training data).
COMPLIANT = Controller(kind=ControllerKind.COMPLIANT)
SERVO = Controller(kind=ControllerKind.SERVO)
#: The values of :attr:`GenerationSettings.wall_push`.
WALL_PUSHES = ("uniform", "wall", "planner")
#: The ``wall_push`` of each shipped model's data, by controller kind (docs/cbst.md): the
#: compliant model learnt the planner's pushes to the wall, the servo's the uniform ones.
SHIPPED_WALL_PUSH: dict[str, str] = {"compliant": "planner", "servo": "uniform"}


@dataclass(frozen=True)
class GenerationSettings:
    """Every number of the example distribution (module docstring). Inches and degrees;
    ``controller`` drives the paddle in every rollout (internal units, ``None`` fields at
    their defaults: :class:`~arrange_up.model.problem.Controller`)."""

    block_size: float = 1.0
    paddle_size: tuple[float, float] = (2.5, 0.15)
    table: tuple[float, float] = (14.0, 10.0)
    domain: Domain = field(default_factory=Domain)
    min_overlap: float = MIN_OVERLAP
    min_overlap_paddle: float = MIN_OVERLAP_PADDLE
    push_margin: float = PUSH_MARGIN
    wall_gap: float = 1.0
    spacing_gap: float = 0.6
    paddle_gap: tuple[float, float] = (0.02, 0.5)
    friction: tuple[float, float] = (0.25, 0.55)
    part_density: tuple[float, float] = (0.1, 0.15)
    manipulator_density: tuple[float, float] = (0.35, 0.45)
    min_ok_fraction: float = 0.9
    max_blocks: int = 3
    controller: Controller = COMPLIANT
    wall_push: str = "uniform"
    """Where the push sends the paddle's front (module docstring): ``"uniform"`` between just
    beyond the compressed train and the wall, ``"wall"`` at the wall, or ``"planner"`` where
    CBST's push to the wall does."""
    quantile: float = 1.0
    """The quantile of the rollouts each target is (:mod:`.features`): 1.0, the largest (the
    thesis's maxima), or a high quantile such as 0.99, so that a target does not widen with
    the number of rollouts per example."""

    def __post_init__(self) -> None:
        if self.wall_push not in WALL_PUSHES:
            raise ValueError(
                f"GenerationSettings.wall_push must be one of {', '.join(WALL_PUSHES)}, "
                f"got {self.wall_push!r}"
            )
        if not 0.5 <= self.quantile <= 1.0:
            raise ValueError(
                f"GenerationSettings.quantile must lie in [0.5, 1], got {self.quantile!r}"
            )

    def as_dict(self) -> dict[str, Any]:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> GenerationSettings:
        """The settings :meth:`as_dict` gave (as a model card stores them); settings without a
        controller predate it and are the servo's."""
        values = dict(data)
        for name, value in values.items():
            if isinstance(value, list):
                values[name] = tuple(value)
        values["domain"] = Domain.from_dict(values["domain"])
        controller = dict(values.get("controller") or {"kind": ControllerKind.SERVO})
        controller["kind"] = ControllerKind(controller["kind"])
        values["controller"] = Controller(**controller)
        return cls(**values)

    def digest(self) -> str:
        """A short hash of every setting. The controller is left out when it is the default
        servo, and ``wall_push`` when it is ``"uniform"``, so that data files (and model
        cards) written before they were settings keep their digest; so is ``quantile`` when it
        is 1.0 (the maxima)."""
        values = self.as_dict()
        if self.controller == SERVO:
            del values["controller"]
        if self.wall_push == "uniform":
            del values["wall_push"]
        if self.quantile == 1.0:
            del values["quantile"]
        text = json.dumps(values, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


DEFAULT_GENERATION = GenerationSettings()


# -- the scene ----------------------------------------------------------------------------------
@cache
def _scene(settings: GenerationSettings):
    """The problem the rollouts are simulated in: blocks b0..b{n-1}, a paddle, four walls."""

    def box(w: float, h: float) -> Shape:
        return Shape(
            parts=(((-w / 2, -h / 2), (w / 2, -h / 2), (w / 2, h / 2), (-w / 2, h / 2)),),
            box=(w, h),
        )

    d = settings.block_size
    objects = [ObjectSpec(f"b{i}", ObjectKind.PART, box(d, d)) for i in range(settings.max_blocks)]
    objects.append(ObjectSpec("paddle", ObjectKind.MANIPULATOR, box(*settings.paddle_size)))
    return ArrangementProblem(
        name="cbst-training",
        table=Table(tuple(settings.table)),  # type: ignore[arg-type]
        objects=tuple(objects),
        initial=(),
        goal=Goal(targets=(), tolerance=(0.1, 0.1, None)),
        controller=settings.controller,
    )


def _square_reach(theta: float) -> float:
    """Half extent, along a fixed axis, of a unit-half-side square turned by ``theta``."""
    return abs(math.cos(theta)) + abs(math.sin(theta))


def _squares_overlap(a: Sequence[float], b: Sequence[float], h: float) -> bool:
    """Separating-axis test for two squares of half side ``h`` at poses ``a`` and ``b``."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    for angle in (a[2], a[2] + 0.5 * math.pi, b[2], b[2] + 0.5 * math.pi):
        nx, ny = math.cos(angle), math.sin(angle)
        dist = abs(dx * nx + dy * ny)
        ra = h * _square_reach(a[2] - angle)
        rb = h * _square_reach(b[2] - angle)
        if dist >= ra + rb:
            return False
    return True


@dataclass(frozen=True)
class _Config:
    n: int
    centers: tuple[tuple[float, float], ...]
    halves: tuple[tuple[float, float, float], ...]  # radians
    paddle_pose: tuple[float, float, float]
    paddle_half: tuple[float, float, float]  # radians
    distance: float
    wall: float


def _draw_config(rng: np.random.Generator, n: int, s: GenerationSettings) -> _Config:
    d = s.block_size
    bh = s.domain.block_half
    halves: list[tuple[float, float, float]] = []
    vs: list[float] = [0.5 * s.table[1]]
    for j in range(n):
        m = 0.0
        for _ in range(1000):
            h = (
                float(rng.uniform(0.0, bh[0])),
                float(rng.uniform(0.0, bh[1])),
                math.radians(float(rng.uniform(0.0, bh[2]))),
            )
            if j == 0:
                break
            m = (d - s.min_overlap) - (halves[-1][1] + h[1])
            if m >= 0.0:
                break
        else:
            # The previous block's dy leaves (almost) no room for a certain contact (a domain
            # wider than d - MIN_OVERLAP): the widest dy that still has one, centred.
            h = (h[0], max(0.0, (d - s.min_overlap) - halves[-1][1]), h[2])
            m = 0.0
        halves.append(h)
        if j > 0:
            vs.append(vs[-1] + float(rng.uniform(-m, m)))
    wall = float(s.table[0])
    us = [0.0] * n
    us[-1] = wall - 0.5 * d - halves[-1][0] - float(rng.uniform(0.0, s.wall_gap))
    for j in range(n - 2, -1, -1):
        tight = -2.0 * min(halves[j][0], halves[j + 1][0])
        gap = float(rng.uniform(tight, s.spacing_gap))
        us[j] = us[j + 1] - (d + halves[j][0] + halves[j + 1][0] + gap)
    ph = s.domain.paddle_half
    paddle_half = (
        float(rng.uniform(0.0, ph[0])),
        float(rng.uniform(0.0, ph[1])),
        math.radians(float(rng.uniform(0.0, ph[2]))),
    )
    reach = 0.5 * s.paddle_size[0] + 0.5 * d - s.min_overlap_paddle
    m_r = max(0.0, min(s.domain.paddle_offset, reach - (paddle_half[1] + halves[0][1])))
    v_r = vs[0] + float(rng.uniform(-m_r, m_r))
    w, t = s.paddle_size
    paddle_parts = (((-w / 2, -t / 2), (w / 2, -t / 2), (w / 2, t / 2), (-w / 2, t / 2)),)
    block_parts = (((-d / 2, -d / 2), (d / 2, -d / 2), (d / 2, d / 2), (-d / 2, d / 2)),)
    front = shadow_box(paddle_parts, (0.0, v_r, EAST), paddle_half)[2]
    first = shadow_box(block_parts, (us[0], vs[0], 0.0), halves[0])[0]
    u_r = first - float(rng.uniform(*s.paddle_gap)) - front
    compressed = wall - n * d
    ref_front = float(rng.uniform(compressed + s.push_margin, wall))
    if s.wall_push == "wall":
        ref_front = wall
    elif s.wall_push == "planner":
        over = wall_overdrive(s.controller, s.friction, s.part_density, n * d * d, paddle_half[0])
        ref_front = wall_push_front(wall, n * d, over)
    distance = ref_front - (u_r + 0.5 * t)
    return _Config(
        n=n,
        centers=tuple(zip(us, vs, strict=True)),
        halves=tuple(halves),
        paddle_pose=(u_r, v_r, EAST),
        paddle_half=paddle_half,
        distance=distance,
        wall=wall,
    )


def _sample_state(rng: np.random.Generator, cfg: _Config, h: float, tries: int):
    """Block poses drawn uniformly from the belief, rejecting collisions; None if ``tries``
    draws all collide."""
    for _ in range(tries):
        poses = []
        for (u, v), (hu, hv, ht) in zip(cfg.centers, cfg.halves, strict=True):
            poses.append(
                (
                    u + float(rng.uniform(-hu, hu)),
                    v + float(rng.uniform(-hv, hv)),
                    float(rng.uniform(-ht, ht)),
                )
            )
        if any(p[0] + h * _square_reach(p[2]) > cfg.wall for p in poses):
            continue
        if any(
            _squares_overlap(poses[i], poses[j], h)
            for i in range(len(poses))
            for j in range(i + 1, len(poses))
        ):
            continue
        return poses
    return None


def _wrap(theta: np.ndarray, period: float) -> np.ndarray:
    return (theta + 0.5 * period) % period - 0.5 * period


def generate_example(
    index: int,
    seed: int,
    rollouts: int,
    settings: GenerationSettings = DEFAULT_GENERATION,
    outcomes: bool = False,
) -> dict[str, Any]:
    """Example ``index`` of the data set of ``seed`` (module docstring), as a JSON-ready dict:
    ``features`` and ``targets`` (one row per block, paddle side first), ``overshoot`` per
    block, rollout counts and whether the example is ``valid`` (enough rollouts at rest);
    with ``outcomes``, also every rollout's deviations per block (``outcomes``, rollouts x 4
    per block, in target order). ``outcomes`` draws no random numbers: the example is the
    same either way."""
    if rollouts < 1:
        raise ValueError("rollouts must be at least 1")
    started = time.perf_counter()
    rng = np.random.default_rng([int(seed), int(index)])
    s = settings
    problem = _scene(s)
    h = 0.5 * s.block_size
    n = int(rng.integers(1, s.max_blocks + 1))
    for _attempt in range(100):
        cfg = _draw_config(rng, n, s)
        probe = sum(_sample_state(rng, cfg, h, 1) is not None for _ in range(40))
        if probe >= 4:
            break
    names = [f"b{j}" for j in range(n)]
    finals: list[list[tuple[float, float, float]]] = []
    failed: dict[str, int] = {}
    for _ in range(rollouts):
        poses = _sample_state(rng, cfg, h, 10_000)
        if poses is None:  # pragma: no cover - the probe makes this practically impossible
            failed["no_state"] = failed.get("no_state", 0) + 1
            continue
        ph = cfg.paddle_half
        pu, pv, pt = cfg.paddle_pose
        pose = (
            pu + float(rng.uniform(-ph[0], ph[0])),
            pv + float(rng.uniform(-ph[1], ph[1])),
            pt + float(rng.uniform(-ph[2], ph[2])),
        )
        noise = ActionNoise(
            (0.0, 0.0, 0.0),
            float(rng.uniform(*s.friction)),
            float(rng.uniform(*s.part_density)),
            float(rng.uniform(*s.manipulator_density)),
        )
        state = WorldState(tuple(zip(names, poses, strict=True)))
        outcome = simulate(problem, state, Push("paddle", pose, cfg.distance), noise)
        if not outcome.ok:
            failed[str(outcome.status)] = failed.get(str(outcome.status), 0) + 1
            continue
        final = outcome.state.as_dict()
        finals.append([final[name] for name in names])
    ok = len(finals)
    record: dict[str, Any] = {
        "format": DATA_FORMAT,
        "settings": s.digest(),
        "seed": int(seed),
        "index": int(index),
        "rollouts": int(rollouts),
        "blocks": n,
        "ok": ok,
        "failed": failed,
        "valid": ok >= max(1, math.ceil(s.min_ok_fraction * rollouts)),
    }
    rows, targets, overshoot, deviations = [], [], [], []
    arr = np.array(finals, dtype=float).reshape(ok, n, 3)
    q = s.quantile
    paddle_half = cfg.paddle_half
    for j in range(n):
        if j == 0:
            prev = (paddle_half, cfg.paddle_pose[1], False)
        else:
            prev = (cfg.halves[j - 1], cfg.centers[j - 1][1], True)
        nxt_half = cfg.halves[j + 1] if j + 1 < n else None
        nxt_v = cfg.centers[j + 1][1] if j + 1 < n else None
        rows.append(
            feature_row(
                prev[0], prev[1], prev[2], cfg.halves[j], cfg.centers[j][1], nxt_half, nxt_v
            )
        )
        if ok:
            x_max = cfg.wall - (n - j - 0.5) * s.block_size
            u, v, th = arr[:, j, 0], arr[:, j, 1], arr[:, j, 2]
            each = np.column_stack(
                (
                    x_max - u,
                    np.abs(v - cfg.centers[j][1]),
                    np.degrees(np.abs(_wrap(th, 0.5 * math.pi))),
                    u - x_max,
                )
            )
            # np.quantile at 1.0 is the largest exactly, so maxima-trained data is unchanged.
            target = np.quantile(each, q, axis=0)
            target[3] = max(0.0, target[3])
            targets.append([float(t) for t in target])
            overshoot.append(float(u.max() - x_max))
            if outcomes:
                deviations.append(np.round(each, 5).tolist())
    record["features"] = rows
    record["targets"] = targets
    record["overshoot"] = overshoot
    if outcomes:
        record["outcomes"] = deviations
    record["seconds"] = round(time.perf_counter() - started, 4)
    return record


# -- the file ------------------------------------------------------------------------------------
def _read_records(path: Path) -> list[dict[str, Any]]:
    """Complete records of a chunk file; a torn last line (an interrupted write) is dropped
    from the file."""
    if not path.exists():
        return []
    with path.open("r+b") as fh:
        # a file of another kind is refused untouched (its first line is no data record)
        lines = recorded_lines(fh, path, DATA_FORMAT, "a CBST data file")
    records = []
    for number, line in enumerate(lines, 1):
        if not line.strip():
            continue
        try:
            records.append(json.loads(line))
        except (json.JSONDecodeError, UnicodeDecodeError) as err:
            raise ValueError(f"{path}:{number}: not a CBST data record ({err})") from err
    return records


def _check_compatible(path: Path, record: dict, seed: int, rollouts: int, digest: str) -> None:
    mismatch = []
    if record.get("format") != DATA_FORMAT:
        mismatch.append(f"format {record.get('format')!r}")
    if record.get("seed") != seed:
        mismatch.append(f"seed {record.get('seed')}")
    if record.get("rollouts") != rollouts:
        mismatch.append(f"rollouts {record.get('rollouts')}")
    if record.get("settings") != digest:
        mismatch.append("generation settings")
    if mismatch:
        raise ValueError(
            f"{path} holds examples generated with other parameters ({', '.join(mismatch)}); "
            f"wanted seed {seed}, rollouts {rollouts}: use another data file"
        )


def generate_dataset(
    path: str | Path,
    *,
    examples: int,
    rollouts: int,
    seed: int = 0,
    workers: int | None = 1,
    backend: str = "local",
    scheduler: str | None = None,
    chunksize: int | None = None,
    settings: GenerationSettings = DEFAULT_GENERATION,
    outcomes: bool = False,
    progress: TrainingProgress | None = None,
) -> dict[str, Any]:
    """Make sure ``path`` holds examples ``0 .. examples-1`` of the data set of ``seed`` with
    ``rollouts`` rollouts each, computing and appending the missing ones (with every
    rollout's deviations when ``outcomes``: :func:`generate_example`).

    ``backend``, ``workers`` (``None``: every core) and ``scheduler`` choose the runner
    (:func:`arrange_up.parallel.get_runner`: ``"local"`` processes or a ``"dask"`` cluster);
    ``chunksize`` examples go to a worker at a time (default: about four chunks per worker,
    at most 8 examples each). Returns a summary: examples present, newly computed, and the
    seconds it took.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    digest = settings.digest()
    done: set[int] = set()
    for record in _read_records(path):
        _check_compatible(path, record, seed, rollouts, digest)
        done.add(int(record["index"]))
    pending = [i for i in range(examples) if i not in done]
    total = examples
    finished = examples - len(pending)
    if progress is not None:
        progress("data", finished, total)
    started = time.monotonic()
    if pending:
        runner = get_runner(backend, workers, scheduler)
        size = chunksize or auto_chunksize(len(pending), runner.workers, most=8)
        task = partial(
            generate_example, seed=seed, rollouts=rollouts, settings=settings, outcomes=outcomes
        )
        with path.open("a", encoding="utf-8") as fh:
            for _index, record in runner.map(task, pending, size):
                fh.write(json.dumps(record, separators=(",", ":")) + "\n")
                fh.flush()  # a killed run keeps every finished example
                finished += 1
                if progress is not None:
                    progress("data", finished, total)
            os.fsync(fh.fileno())
    return {
        "path": str(path),
        "examples": examples,
        "computed": len(pending),
        "seconds": time.monotonic() - started,
    }


@dataclass(frozen=True)
class Dataset:
    """Rows of a data file: features ``X`` (rows x 12), targets ``y`` (rows x 4), the example
    index of each row (``groups``), and per-file statistics. ``outcomes``: per row, its
    rollouts' deviations (rollouts x 4, :func:`generate_example`), when every valid record
    of the file kept them; else None."""

    X: np.ndarray
    y: np.ndarray
    groups: np.ndarray
    overshoot: np.ndarray
    examples: int
    invalid: int
    rollouts: int
    failed_rollouts: int
    example_seconds: float
    outcomes: list[np.ndarray] | None = None


def load_dataset(
    path: str | Path,
    *,
    examples: int | None = None,
    seed: int | None = None,
    rollouts: int | None = None,
    settings: GenerationSettings = DEFAULT_GENERATION,
) -> Dataset:
    """Read a data file into arrays, examples in index order (only indices below ``examples``
    when given). ``seed`` and ``rollouts``, when given, must match the file's."""
    path = Path(path)
    records = _read_records(path)
    if not records:
        raise ValueError(f"{path}: no examples")
    first = records[0]
    _check_compatible(
        path,
        first,
        first["seed"] if seed is None else seed,
        first["rollouts"] if rollouts is None else rollouts,
        settings.digest(),
    )
    for record in records:
        _check_compatible(path, record, first["seed"], first["rollouts"], settings.digest())
    by_index = {int(r["index"]): r for r in records}
    chosen = [by_index[i] for i in sorted(by_index) if examples is None or i < examples]
    return _arrays(chosen, int(first["rollouts"]))


def _arrays(records: Iterable[dict[str, Any]], rollouts: int) -> Dataset:
    X, y, groups, over = [], [], [], []
    outcomes: list[np.ndarray] | None = []
    n = invalid = failed = 0
    seconds = 0.0
    for record in records:
        n += 1
        failed += sum(record["failed"].values())
        seconds += float(record.get("seconds", 0.0))
        if not record["valid"]:
            invalid += 1
            continue
        X.extend(record["features"])
        y.extend(record["targets"])
        over.extend(record["overshoot"])
        groups.extend([record["index"]] * len(record["targets"]))
        if outcomes is not None and "outcomes" in record:
            outcomes.extend(np.asarray(o, dtype=float).reshape(-1, 4) for o in record["outcomes"])
        else:
            outcomes = None
    return Dataset(
        X=np.asarray(X, dtype=float).reshape(-1, 12),
        y=np.asarray(y, dtype=float).reshape(-1, 4),
        groups=np.asarray(groups, dtype=int),
        overshoot=np.asarray(over, dtype=float),
        examples=n,
        invalid=invalid,
        rollouts=rollouts,
        failed_rollouts=failed,
        example_seconds=seconds,
        outcomes=outcomes,
    )
