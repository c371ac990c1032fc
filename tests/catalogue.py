"""A catalogue of tiny problems that tests pick by name.

Each entry is YAML text in the problem format (``docs/problem-format.md``), loaded through the
public loader (refusing warnings too), so the catalogue exercises the same path users take.
Entries are as small as the concern they serve allows (one or two parts, one paddle, small
tables), so that tests built on them stay fast.

From a test, either take the fixtures of ``tests/conftest.py`` (``tiny`` is :func:`tiny`;
``problem`` is parametrised indirectly by name) or import this module directly
(``from catalogue import tiny``): pytest puts ``tests/`` on the path for its ``conftest.py``.

Problems are frozen dataclasses, so one loaded problem is shared by every test that asks for it.
:func:`particle_task` builds the search task the planner would for a problem, for tests of the
candidates and beliefs it sees.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterator
from contextlib import contextmanager
from functools import cache

from arrange_up.belief.compiled import compile_problem
from arrange_up.io.yaml_problem import check_problem_text
from arrange_up.model.problem import SERVO_CONTROLLER, ArrangementProblem
from arrange_up.planning.config import PlanConfig
from arrange_up.planning.task import BeliefTask

TEXTS: dict[str, str] = {
    # One block to the lower-right corner of a small walled board; starts off the table.
    "one-block": """
name: one-block
table: {size: [5, 3]}
objects:
  A: {kind: part, shape: {box: [1, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
goal:
  tolerance: [0.2, 0.2, 15]
  poses: {A: [4.5, 0.5, 0]}
uncertainty: {place: [0.2, 0.2, 15], push: [0.05, 0.05, 3]}
""",
    # The same problem written in millimetres (every length times 25.4): loads to the same
    # problem in inches, and results are written back in millimetres.
    "millimetres": """
name: millimetres
units: {length: mm, angle: deg}
table: {size: [127, 76.2]}
objects:
  A: {kind: part, shape: {box: [25.4, 25.4]}}
  paddle: {kind: manipulator, shape: {box: [63.5, 3.81]}}
goal:
  tolerance: [5.08, 5.08, 15]
  poses: {A: [114.3, 12.7, 0]}
uncertainty: {place: [5.08, 5.08, 15], push: [1.27, 1.27, 3]}
""",
    # Two blocks in a row along the bottom wall of the 10 x 5 in board (blocks-2 without its
    # friction and density ranges); B must end left of A.
    "two-blocks-row": """
name: two-blocks-row
table: {size: [10, 5]}
objects:
  A: {kind: part, shape: {box: [1, 1]}}
  B: {kind: part, shape: {box: [1, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
goal:
  tolerance: [0.2, 0.2, 15]
  poses: {A: [9.5, 0.5, 0], B: [8.5, 0.5, 0]}
uncertainty: {place: [0.2, 0.2, 15], push: [0.05, 0.05, 3]}
""",
    # One block and a fixture (a fence) already on the table, away from the block's goal.
    "block-and-fixture": """
name: block-and-fixture
table: {size: [6, 4]}
objects:
  A: {kind: part, shape: {box: [1, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
  bar: {kind: fixture, shape: {box: [0.5, 2]}}
initial:
  bar: {pose: [1, 2, 0]}
goal:
  tolerance: [0.2, 0.2, 15]
  poses: {A: [5.5, 0.5, 0]}
uncertainty: {place: [0.2, 0.2, 15], push: [0.05, 0.05, 3]}
""",
    # Two cubes lying on a walled 16 x 10 in board, to be put in a row one inch above the bottom
    # wall (the second row of a pack whose first row is not asked for), F left of G; F lies
    # right of G at the start, so the ordering filter calls the start a dead end although
    # either cube can be pushed out of the other's row.
    "second-row-pair": """
name: second-row-pair
table: {size: [16, 10]}
objects:
  F: {kind: part, shape: {box: [1, 1]}}
  G: {kind: part, shape: {box: [1, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
initial:
  F: {pose: [11, 3.5, 0], uncertainty: [0.2, 0.2, 10]}
  G: {pose: [7, 4, 0], uncertainty: [0.2, 0.2, 10]}
goal:
  tolerance: [0.2, 0.2, 15]
  poses: {F: [0.5, 1.5, 0], G: [1.5, 1.5, 0]}
uncertainty: {place: [0.2, 0.2, 15], push: [0.05, 0.05, 3]}
""",
    # A non-convex L-shaped part (two convex pieces after decomposition), starting on the table.
    "l-part": """
name: l-part
table: {size: [6, 4]}
shapes:
  ell: {polygon: [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]}
objects:
  L: {kind: part, shape: ell}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
initial:
  L: {pose: [2, 2, 0], uncertainty: [0.1, 0.1, 5]}
goal:
  tolerance: [0.2, 0.2, 15]
  poses: {L: [4, 1, 0]}
uncertainty: {place: [0.2, 0.2, 15], push: [0.05, 0.05, 3]}
""",
    # A relative goal: U one tee-width to the right of the tee T, wherever T ends; no walls,
    # no manipulator (tests of goals, particles and place targets only).
    "relative-goal": """
name: relative-goal
table: {size: [12, 12], walls: []}
shapes:
  tee: {polygon: [[0,0],[3,0],[3,1],[2,1],[2,3],[1,3],[1,1],[0,1]]}
objects:
  T: {kind: part, shape: tee}
  U: {kind: part, shape: {box: [1, 1]}}
initial:
  T: {pose: [4, 4, 0], uncertainty: [0.3, 0.3, 5]}
  U: {pose: [8, 8, 0], uncertainty: [0.3, 0.3, 5]}
goal:
  tolerance: [0.1, 0.1, 5]
  relative: {reference: T, poses: {U: [2.0, 0.0, 0]}}
""",
    # One block and a fixed post between the block's start and its goal, on a board walled
    # only on the left and bottom.
    "obstacle": """
name: obstacle
table: {size: [6, 4], walls: [left, bottom]}
objects:
  A: {kind: part, shape: {box: [1, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
  post: {kind: obstacle, shape: {box: [1, 1]}, pose: [3, 0.5, 0]}
initial:
  A: {pose: [1, 2, 0], uncertainty: [0.1, 0.1, 5]}
goal:
  tolerance: [0.2, 0.2, 15]
  poses: {A: [5, 0.5, 0]}
uncertainty: {place: [0.2, 0.2, 15], push: [0.05, 0.05, 3]}
""",
    # The tutorial's problem (docs/tutorial.md): an L and a box into a walled corner, with a
    # fixture; a fixture or a longer push chosen for the belief can make its nominal plan miss.
    "ell-and-box": """
name: ell-and-box
table: {size: [8, 5], walls: [left, right, bottom, top]}
shapes:
  ell:
    polygon: [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
objects:
  L: {kind: part, shape: ell}
  B: {kind: part, shape: {box: [1, 1]}}
  paddle: {kind: manipulator, shape: {box: [2.5, 0.15]}}
  bar: {kind: fixture, shape: {box: [2, 0.5]}}
initial:
  L: {pose: [2.5, 2.5, 0], uncertainty: [0.2, 0.2, 10]}
goal:
  tolerance: [0.2, 0.2, 15]
  poses: {L: [6.83, 0.83, 0], B: [7.5, 1.5, 0]}
uncertainty:
  place: [0.2, 0.2, 15]
  push: [0.05, 0.05, 3]
  friction: [0.25, 0.55]
""",
    # A millimetre-scale chip and an 8 x 0.5 mm paddle (mass about 0.0025): the compliant
    # controller's default kp is far too stiff for it (physics.simulation.stiff_manipulators).
    "millimetre-paddle": """
name: millimetre-paddle
units: {length: mm}
table: {size: [40, 20]}
objects:
  chip: {kind: part, shape: {box: [5, 3]}}
  tip: {kind: manipulator, shape: {box: [8, 0.5]}}
initial: {chip: {pose: [20, 10, 0], uncertainty: [0.5, 0.5, 5]}}
goal: {tolerance: [0.5, 0.5, 10], poses: {chip: [37.5, 1.5, 0]}}
""",
}

NAMES: tuple[str, ...] = tuple(TEXTS)


def text(name: str) -> str:
    """The YAML text of catalogue entry ``name`` (to derive a variant by editing it)."""
    try:
        return TEXTS[name]
    except KeyError:
        raise KeyError(
            f"no tiny problem {name!r} in the catalogue; expected one of {', '.join(NAMES)}"
        ) from None


@cache
def tiny(name: str) -> ArrangementProblem:
    """Catalogue entry ``name``, loaded (once) through the public YAML loader."""
    return _load(text(name), f"catalogue:{name}")


def variant(name: str, old: str, new: str) -> ArrangementProblem:
    """Catalogue entry ``name`` with the text ``old`` (which must occur exactly once) replaced
    by ``new``."""
    base = text(name)
    if base.count(old) != 1:
        raise ValueError(f"{old!r} occurs {base.count(old)} times in catalogue entry {name!r}")
    return _load(base.replace(old, new), f"catalogue:{name}*")


def with_planning(name: str, hints: str) -> ArrangementProblem:
    """Catalogue entry ``name`` with the ``planning:`` hints ``hints`` (a YAML flow mapping,
    e.g. ``'{push_distances: [0.5]}'``); no entry has hints of its own."""
    return _load(f"{text(name)}planning: {hints}\n", f"catalogue:{name}+planning")


def servo(problem: ArrangementProblem) -> ArrangementProblem:
    """``problem`` driven by the servo: for tests of rules stated for a push that ends where it
    was sent (the default compliant controller stops short: tests/planning/test_stall_aware.py)."""
    return dataclasses.replace(problem, controller=SERVO_CONTROLLER)


@contextmanager
def particle_task(
    problem: ArrangementProblem, particles: int, seed: int = 0
) -> Iterator[BeliefTask]:
    """The search task ``plan(problem, particles=particles, seed=seed, workers=1)`` builds
    (particle semantics, the inadmissible heuristic, dominance, no variety), closed on leaving."""
    task = BeliefTask.build(compile_problem(problem), PlanConfig(particles=particles, seed=seed))
    try:
        yield task
    finally:
        task.close()


def _load(yaml_text: str, source: str) -> ArrangementProblem:
    # Warnings are refused too: a misspelt optional key (``uncertainity:``) is only a warning
    # to the loader, and would silently turn a tiny problem into another one.
    problem, diagnostics = check_problem_text(yaml_text, source)
    if diagnostics:
        raise ValueError("\n".join(str(d) for d in diagnostics))
    assert problem is not None
    return problem
