"""The house rule: each room of the package imports only rooms below it.

A room is a sub-package of ``arrange_up`` (or a top-level module such as ``search``);
``benchmarks/house.py``'s ``ROOMS`` lists them bottom-up, rooms on one line being peers that must
not import each other. Every import of the package's own modules counts, at module level or
inside a function. The package's ``__init__`` and ``__main__`` sit above every room; the package
root itself may be imported anywhere for its ``__version__``.
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from house import ROOMS  # noqa: E402  (the room order is written once, in benchmarks/house.py)

PACKAGE_DIR = Path(__file__).resolve().parents[1] / "arrange_up"

TOP = ("__init__", "__main__")
ROOT_METADATA = ("arrange_up", "arrange_up.__version__")
LEVEL = {room: level for level, rooms in enumerate(ROOMS) for room in rooms}


def _room(module: str) -> str:
    """``arrange_up.io.pddl`` -> ``io``."""
    return module.split(".")[1] if module.count(".") else "__init__"


def _imports(path: Path) -> list[tuple[int, str]]:
    """(line, module) of every import of the package's own modules in ``path``."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("arrange_up"):
            names = (
                [node.module]
                if node.module != "arrange_up"
                else [f"arrange_up.{alias.name}" for alias in node.names]
            )
            found += [(node.lineno, name) for name in names]
        elif isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names if a.name.startswith("arrange_up")]
    return [(line, name) for line, name in found if name not in ROOT_METADATA]


def _modules() -> list[Path]:
    return sorted(PACKAGE_DIR.rglob("*.py"))


def _room_of(path: Path) -> str:
    """The room of module ``path``: its sub-package of ``arrange_up`` (a package nested in a
    room, such as ``planning/generators``, is part of that room), or a top-level module's name."""
    parts = path.relative_to(PACKAGE_DIR).parts
    return parts[0] if len(parts) > 1 else path.stem


def test_every_room_is_placed() -> None:
    rooms = {_room_of(p) for p in _modules()}
    assert rooms - set(LEVEL) - set(TOP) == set()


@pytest.mark.parametrize("path", _modules(), ids=lambda p: str(p.relative_to(PACKAGE_DIR)))
def test_rooms_import_only_rooms_below(path: Path) -> None:
    room = _room_of(path)
    if room in TOP:
        return
    upward = [
        f"line {line}: {module}"
        for line, module in _imports(path)
        if _room(module) != room
        and (_room(module) in TOP or LEVEL.get(_room(module), -1) >= LEVEL[room])
    ]
    assert upward == [], f"{room} imports rooms at or above its own"
