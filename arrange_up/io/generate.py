"""Generated problems: YAML problem files of documented families, any number of parts.

:func:`generate_problem` writes the text of a problem file (``docs/problem-format.md``) in the
block world of the shipped construction problems (thesis ch. 3 on the set-up of §2.4.2: 1-inch
blocks placed by the robot and pushed with a 2.5 x 0.15 in paddle, walls on all four sides,
the same tolerance and noise), on a table grown with the number of parts. The families
(:data:`FAMILIES`; ``docs/generated-problems.md`` describes how each is laid out):

* ``row``: a row of blocks along a long wall, into a corner;
* ``staircase``: rows into a corner, each one block shorter than the row below;
* ``pack``: a rectangular pack of rows into a corner;
* ``wall-row``: a row against one long wall, away from the corners;
* ``mixed``: boxes and L and T tetrominoes, in a row along the bottom wall and a row along the
  top wall, each from one corner;
* ``relative``: blocks flush with one another relative to a reference block, anywhere.

Every part starts off the table (the robot places it), and the parts are named ``A``, ``B``,
... in the order they are built: a part after those it is pressed against. The seed chooses
what the family leaves open (the corner, the wall, the row's place along it, the mix and order
of shapes, the relative arrangement's outline): the same arguments give the same text, byte
for byte, on every platform (only :meth:`random.Random.random` is drawn from, whose sequence
Python keeps across versions).
"""

from __future__ import annotations

import math
import random
import textwrap
from collections.abc import Sequence
from dataclasses import dataclass, field

__all__ = [
    "BLOCKS_NOISE",
    "FAMILIES",
    "MAX_PARTS",
    "Noise",
    "generate_problem",
    "min_parts",
    "part_names",
]

#: family -> one line on what it builds
FAMILIES: dict[str, str] = {
    "row": "a row of 1-inch blocks along a long wall, into a corner",
    "staircase": "rows into a corner, each one block shorter than the row below",
    "pack": "a rectangular pack of rows of blocks into a corner, about twice as wide as deep",
    "wall-row": "a row of blocks against one long wall, away from the corners",
    "mixed": "boxes, bars and L and T tetrominoes in rows along the bottom and top walls",
    "relative": "blocks flush with one another relative to a reference block, anywhere",
}

#: The most parts a generated problem has: beyond it the tables grow past any real robot's
#: reach (a row of 50 blocks is a 54 in table).
MAX_PARTS = 50

#: Families that need more than one part: a relative goal places parts relative to another.
MIN_PARTS = {"relative": 2}


def min_parts(family: str) -> int:
    """The fewest parts a problem of ``family`` has."""
    return MIN_PARTS.get(family, 1)


#: The block world's table, the smallest a generated problem gets (width, depth in inches).
MIN_TABLE = (10.0, 5.0)
#: Free room kept beside a row along its wall, and above the arrangement (inches): the block
#: world's 10 x 5 in table leaves 4 in beside blocks-9's row of six and 3 in above its two rows.
ROOM_BESIDE = 4.0
ROOM_ABOVE = 3.0
#: A wall-row's ends keep at least this much room from the side walls, so that neither end is
#: held by a wall (more than the paddle's length).
END_ROOM = 3.0

TOLERANCE = (0.2, 0.2, 15.0)  # the real-robot experiments' (thesis §3.3)
PADDLE = (2.5, 0.15)  # the custom PR2 paddle (thesis Figure 2-18)


@dataclass(frozen=True)
class Noise:
    """The nondeterminism of a generated problem (the ``uncertainty:`` section; inches and
    degrees): ``place`` and ``push`` half-widths ``(dx, dy, dtheta)``, the ``friction`` range
    and the density ranges."""

    place: tuple[float, float, float] = (0.2, 0.2, 15.0)
    push: tuple[float, float, float] = (0.05, 0.05, 3.0)
    friction: tuple[float, float] = (0.25, 0.55)
    part_density: tuple[float, float] = (0.1, 0.15)
    manipulator_density: tuple[float, float] = (0.35, 0.45)


#: The shipped block problems' noise: place as measured on the PR2 (thesis Figure 2-21), push
#: the project's choice, friction the push model's training range (§3.2), Table 4.2's densities.
BLOCKS_NOISE = Noise()


@dataclass(frozen=True)
class _Shape:
    """A part's shape: its YAML text, its size (w x h, inches, at angle 0) and the offset of
    its centroid (the pose's point) from its lower-left corner."""

    yaml: str
    width: float
    height: float
    centroid: tuple[float, float]
    named: str | None = None  # the key of a `shapes:` entry, for polygons


BLOCK = _Shape("{box: [1, 1]}", 1.0, 1.0, (0.5, 0.5))
BAR = _Shape("{box: [2, 1]}", 2.0, 1.0, (1.0, 0.5))
# Tetrominoes of 1-inch squares with a flat 3-inch base, so that they sit flush on a wall and
# against their neighbours; their centroids fall on quarter inches, so goal poses are exact.
ELL = _Shape("ell", 3.0, 2.0, (1.25, 0.75), "ell")
TEE = _Shape("tee", 3.0, 2.0, (1.5, 0.75), "tee")
POLYGONS = {
    "ell": "[[0, 0], [3, 0], [3, 1], [1, 1], [1, 2], [0, 2]]",
    "tee": "[[0, 0], [3, 0], [3, 1], [2, 1], [2, 2], [1, 2], [1, 1], [0, 1]]",
}
POLYGON_NOTES = {
    "ell": "L tetromino; centroid (1.25, 0.75)",
    "tee": "T tetromino; centroid (1.5, 0.75)",
}


@dataclass
class _Layout:
    """A family's goal, before it is written: the table, the parts' shapes and goal poses
    (inches, degrees; in building order), a relative goal's reference, and the description."""

    size: tuple[float, float]
    description: str
    shapes: list[_Shape] = field(default_factory=list)
    poses: list[tuple[float, float, float]] = field(default_factory=list)
    relative: bool = False

    def add(self, shape: _Shape, pose: tuple[float, float, float]) -> None:
        self.shapes.append(shape)
        self.poses.append(pose)


class _Draws:
    """The seed's choices, from :meth:`random.Random.random` alone (see the module doc)."""

    def __init__(self, family: str, parts: int, seed: int) -> None:
        self._random = random.Random(f"arrange-up generate {family} {parts} {seed}")

    def index(self, n: int) -> int:
        """A uniform choice among ``n``."""
        return min(int(self._random.random() * n), n - 1)

    def shuffled(self, items: Sequence[object]) -> list[object]:
        """``items`` in a uniformly random order (Fisher-Yates)."""
        out = list(items)
        for i in range(len(out) - 1, 0, -1):
            j = self.index(i + 1)
            out[i], out[j] = out[j], out[i]
        return out


def part_names(count: int) -> list[str]:
    """``A`` ... ``Z``, then ``AA``, ``AB``, ... (spreadsheet columns): ``count`` part names."""
    names = []
    for k in range(count):
        name, n = "", k + 1
        while n:
            n, r = divmod(n - 1, 26)
            name = chr(ord("A") + r) + name
        names.append(name)
    return names


#: corner -> (x from the right wall?, y from the bottom wall?) and its name
CORNERS = (
    ((True, True), "lower-right"),
    ((False, True), "lower-left"),
    ((True, False), "upper-right"),
    ((False, False), "upper-left"),
)


def _table(width: float, depth: float) -> tuple[float, float]:
    return max(MIN_TABLE[0], width), max(MIN_TABLE[1], depth)


def _cells_into_corner(
    rows: Sequence[int], draws: _Draws, what: str
) -> tuple[_Layout, list[tuple[int, int]]]:
    """A layout of 1-inch blocks in rows of the given lengths (bottom row first, each flush
    with the side wall of a corner the seed chooses): the cells ``(column, row)`` counted from
    the corner, in building order (row by row, from the corner out)."""
    (from_right, from_bottom), corner = CORNERS[draws.index(len(CORNERS))]
    width, depth = _table(max(rows) + ROOM_BESIDE, len(rows) + ROOM_ABOVE)
    layout = _Layout((width, depth), f"{what}, built into the {corner} corner of the walled board.")
    cells = [(i, j) for j, length in enumerate(rows) for i in range(length)]
    for i, j in cells:
        x = width - 0.5 - i if from_right else 0.5 + i
        y = 0.5 + j if from_bottom else depth - 0.5 - j
        layout.add(BLOCK, (x, y, 0.0))
    return layout, cells


def _row(parts: int, draws: _Draws) -> _Layout:
    return _cells_into_corner(
        [parts], draws, f"{parts} blocks in a row along the wall, flush with each other"
    )[0]


def staircase_rows(parts: int) -> list[int]:
    """The row lengths of a ``staircase`` of ``parts`` blocks, bottom row first: the bottom row
    is the shortest ``L`` with ``L + (L - 1) + ... + 1 >= parts``, each row above one shorter,
    the top row whatever remains."""
    length = math.ceil((math.sqrt(8 * parts + 1) - 1) / 2)
    rows, left = [], parts
    while left:
        rows.append(min(length, left))
        left -= rows[-1]
        length -= 1
    return rows


def _staircase(parts: int, draws: _Draws) -> _Layout:
    rows = staircase_rows(parts)
    lengths = " + ".join(str(r) for r in rows)
    return _cells_into_corner(
        rows,
        draws,
        f"{parts} blocks as a staircase of {len(rows)} row{'s' if len(rows) > 1 else ''} "
        f"({lengths} blocks from the wall up), each row flush with the side wall and the row "
        "below",
    )[0]


def pack_rows(parts: int) -> list[int]:
    """The row lengths of a ``pack`` of ``parts`` blocks, bottom row first: ``ceil(sqrt(parts
    / 2))`` rows of ``ceil(parts / rows)`` blocks, the top row holding what remains."""
    count = math.ceil(math.sqrt(parts / 2))
    length = math.ceil(parts / count)
    rows, left = [], parts
    while left:
        rows.append(min(length, left))
        left -= rows[-1]
    return rows


def _pack(parts: int, draws: _Draws) -> _Layout:
    rows = pack_rows(parts)
    return _cells_into_corner(
        rows,
        draws,
        f"{parts} blocks as a pack of {len(rows)} row{'s' if len(rows) > 1 else ''} of "
        f"{rows[0]}" + (f" (the top row {rows[-1]})" if rows[-1] != rows[0] else ""),
    )[0]


def _wall_row(parts: int, draws: _Draws) -> _Layout:
    width, depth = _table(parts + 2 * (END_ROOM + 1.0), 1.0 + ROOM_ABOVE)
    bottom = draws.index(2) == 0
    # the row's left end, on a half-inch grid, at least END_ROOM + 1 in from either side wall
    slots = int((width - parts - 2 * (END_ROOM + 1.0)) / 0.5) + 1
    start = END_ROOM + 1.0 + 0.5 * draws.index(slots)
    wall = "bottom" if bottom else "top"
    layout = _Layout(
        (width, depth),
        f"{parts} blocks in a row along the {wall} wall of the walled board, flush with each "
        f"other, from x = {_number(start)} in: neither end is held by a wall, so the row's "
        "place along the wall is only as certain as the places and pushes make it.",
    )
    for i in range(parts):
        layout.add(BLOCK, (start + 0.5 + i, 0.5 if bottom else depth - 0.5, 0.0))
    return layout


def _mixed(parts: int, draws: _Draws) -> _Layout:
    polygons = (parts + 1) // 2
    kinds = [ELL if k % 2 == 0 else TEE for k in range(polygons)]
    kinds += [BLOCK if k % 2 == 0 else BAR for k in range(parts - polygons)]
    order: list[_Shape] = draws.shuffled(kinds)  # type: ignore[assignment]
    from_right = draws.index(2) == 0
    bottom, top = order[: (parts + 1) // 2], order[(parts + 1) // 2 :]
    row_width = max(sum(s.width for s in row) for row in (bottom, top) if row)
    heights = sum(max((s.height for s in row), default=0.0) for row in (bottom, top))
    width, depth = _table(row_width + ROOM_BESIDE, heights + ROOM_ABOVE)
    side = "right" if from_right else "left"
    layout = _Layout(
        (width, depth),
        f"{parts} parts (1-inch blocks, 2 x 1 in bars, and L and T tetrominoes of 1-inch "
        f"squares), flush with each other in a row of {len(bottom)} along the bottom wall and "
        f"a row of {len(top)} (turned over) along the top wall, each from the {side} wall.",
    )
    for row, on_bottom in ((bottom, True), (top, False)):
        edge = 0.0  # how far the row reaches from the side wall so far
        for shape in row:
            cx, cy = shape.centroid
            # turned over (180 deg), a shape's centroid is (w - cx, h - cy) from its corner
            ox, oy = (cx, cy) if on_bottom else (shape.width - cx, shape.height - cy)
            from_wall = edge + (shape.width - ox if from_right else ox)
            x = width - from_wall if from_right else from_wall
            y = oy if on_bottom else depth - oy
            layout.add(shape, (x, y, 0.0 if on_bottom else 180.0))
            edge += shape.width
    return layout


def relative_cells(parts: int, draws: _Draws) -> list[tuple[int, int]]:
    """A relative goal's outline: ``parts`` unit cells ``(column, row)`` from ``(0, 0)``, the
    reference's, each added at a corner of what is there (a Young diagram: row lengths never
    grow upwards), chosen uniformly, so that each new block touches at most two (the one on its
    left and the one below) and none goes into a slot."""
    cells = [(0, 0)]
    taken = set(cells)
    while len(cells) < parts:
        corners = sorted(
            (i, j)
            for i, j in {(i + 1, j) for i, j in cells} | {(i, j + 1) for i, j in cells}
            if (i, j) not in taken
            and (i == 0 or (i - 1, j) in taken)
            and (j == 0 or (i, j - 1) in taken)
        )
        cell = corners[draws.index(len(corners))]
        cells.append(cell)
        taken.add(cell)
    return cells


def _relative(parts: int, draws: _Draws) -> _Layout:
    cells = relative_cells(parts, draws)
    columns = 1 + max(i for i, _ in cells)
    rows = 1 + max(j for _, j in cells)
    layout = _Layout(
        _table(columns + 2 * ROOM_BESIDE, rows + 2 * ROOM_ABOVE),
        f"{parts} blocks flush with one another in an outline {columns} wide and {rows} deep "
        "(rows that never grow upwards), relative to the reference block A at its lower-left "
        "corner: the arrangement may end anywhere on the walled board.",
        relative=True,
    )
    for i, j in cells:
        layout.add(BLOCK, (float(i), float(j), 0.0))
    return layout


_BUILDERS = {
    "row": _row,
    "staircase": _staircase,
    "pack": _pack,
    "wall-row": _wall_row,
    "mixed": _mixed,
    "relative": _relative,
}
assert set(_BUILDERS) == set(FAMILIES)


def generate_problem(family: str, parts: int, seed: int = 0, *, noise: Noise = BLOCKS_NOISE) -> str:
    """The YAML text of a problem of ``family`` (a key of :data:`FAMILIES`) with ``parts``
    parts, laid out as the seed chooses, with ``noise`` (the shipped block problems' by
    default).

    The problem is named ``FAMILY-PARTS-sSEED``; its description says what it is and the
    command that writes it again. The text is a valid problem file (it loads without errors or
    warnings, with the default ``noise``). Raises ``ValueError`` for an unknown family,
    ``parts`` outside ``min_parts(family) .. MAX_PARTS`` or a negative seed.
    """
    if family not in FAMILIES:
        raise ValueError(f"unknown family {family!r}; expected one of {', '.join(FAMILIES)}")
    fewest = min_parts(family)
    if isinstance(parts, bool) or not isinstance(parts, int) or not fewest <= parts <= MAX_PARTS:
        raise ValueError(
            f"a {family} problem has from {fewest} to {MAX_PARTS} parts, got {parts!r}"
        )
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ValueError(f"seed must be a non-negative integer, got {seed!r}")
    layout = _BUILDERS[family](parts, _Draws(family, parts, seed))
    return _yaml(f"{family}-{parts}-s{seed}", family, parts, seed, layout, noise)


def _number(value: float) -> str:
    """A number as the shipped files write it: no trailing zeros (``9.5``, ``0``, ``0.125``)."""
    text = f"{round(value, 6):.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def _numbers(values: Sequence[float]) -> str:
    return "[" + ", ".join(_number(v) for v in values) + "]"


def _yaml(name: str, family: str, parts: int, seed: int, layout: _Layout, noise: Noise) -> str:
    width, depth = layout.size
    names = part_names(parts)
    world = (
        f"Generated by `arrange-up generate {family} --parts {parts} --seed {seed}` "
        "(docs/generated-problems.md): "
        + layout.description
        + f" The block world of the shipped problems on a {_number(width)} x {_number(depth)} in "
        "board walled on all four sides: every part starts off the table and is placed by the "
        "robot, and pushed with the 2.5 x 0.15 in paddle."
    )
    lines = [
        "format: arrange-up/1",
        f"name: {name}",
        "description: >-",
        textwrap.fill(world, width=98, initial_indent="  ", subsequent_indent="  "),
        "units: {length: in, angle: deg}",
        "",
        "table:",
        f"  size: {_numbers(layout.size)}",
        "  walls: [left, right, bottom, top]",
        "",
    ]
    polygons = sorted({s.named for s in layout.shapes if s.named})
    if polygons:
        lines.append("shapes:")
        lines += [
            f"  {key}: {{polygon: {POLYGONS[key]}}}   # {POLYGON_NOTES[key]}" for key in polygons
        ]
        lines.append("")
    lines.append("objects:")
    shapes = zip(names, layout.shapes, strict=True)
    lines += [f"  {n}: {{kind: part, shape: {s.yaml}}}" for n, s in shapes]
    lines += [
        f"  paddle: {{kind: manipulator, shape: {{box: {_numbers(PADDLE)}}}}}",
        "",
        "initial: {}    # every part starts off the table; the robot places them",
        "",
        "goal:",
        f"  tolerance: {_numbers(TOLERANCE)}",
    ]
    targets = list(zip(names, layout.poses, strict=True))
    if layout.relative:
        lines += ["  relative:", f"    reference: {names[0]}", "    poses:"]
        lines += [f"      {n}: {_numbers(pose)}" for n, pose in targets[1:]]
    else:
        lines.append("  poses:")
        lines += [f"    {n}: {_numbers(pose)}" for n, pose in targets]
    lines += [
        "",
        "uncertainty:",
        f"  place: {_numbers(noise.place)}",
        f"  push: {_numbers(noise.push)}",
        f"  friction: {_numbers(noise.friction)}",
        f"  part_density: {_numbers(noise.part_density)}",
        f"  manipulator_density: {_numbers(noise.manipulator_density)}",
    ]
    return "\n".join(lines) + "\n"
