"""Figures of the package's structure: modules, the largest module and class, and the imports of
the package's own modules that hide inside function bodies.

    python benchmarks/house.py            # the checkout this file is in
    python benchmarks/house.py PATH       # another checkout (its arrange_up/ folder)

Counts are read from the source with :mod:`ast` (nothing is imported). An import of the package's
own modules inside a function counts once per statement; ``if TYPE_CHECKING:`` blocks at module
level are not function bodies and do not count there, but do in the second count, which is every
indented import statement of the package's own modules (any block: functions, ``if``, ``try``).
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

PACKAGE = "arrange_up"


def _own(node: ast.Import | ast.ImportFrom) -> bool:
    if isinstance(node, ast.ImportFrom):
        return node.level > 0 or (node.module or "").split(".")[0] == PACKAGE
    return any(alias.name.split(".")[0] == PACKAGE for alias in node.names)


def _local_imports(tree: ast.AST) -> list[int]:
    """Line numbers of imports of the package's own modules inside function bodies."""
    lines = []
    for func in ast.walk(tree):
        if isinstance(func, ast.FunctionDef | ast.AsyncFunctionDef):
            for node in ast.walk(func):
                if isinstance(node, ast.Import | ast.ImportFrom) and _own(node):
                    lines.append(node.lineno)
    return sorted(set(lines))


def _indented_imports(tree: ast.Module) -> int:
    """Imports of the package's own modules anywhere but at the top level of the module."""
    top = {id(node) for node in tree.body}
    return sum(
        1
        for node in ast.walk(tree)
        if isinstance(node, ast.Import | ast.ImportFrom) and _own(node) and id(node) not in top
    )


def measure(root: Path) -> dict[str, object]:
    package = root / PACKAGE
    modules = sorted(package.rglob("*.py"))
    largest_module = max(modules, key=lambda p: len(p.read_text().splitlines()))
    largest_class, class_lines, local, indented = ("", 0), 0, 0, 0
    for path in modules:
        tree = ast.parse(path.read_text())
        local += len(_local_imports(tree))
        indented += _indented_imports(tree)
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef):
                size = node.end_lineno - node.lineno + 1
                if size > class_lines:
                    largest_class, class_lines = (str(path.relative_to(root)), node.name), size
    return {
        "modules": len(modules),
        "packages": len({p.parent for p in modules}),
        "largest module": f"{largest_module.relative_to(root)} "
        f"({len(largest_module.read_text().splitlines())} lines)",
        "largest class": f"{largest_class[0]}:{largest_class[1]} ({class_lines} lines)",
        "function-local imports of the package's own modules": local,
        "indented imports of the package's own modules (any block)": indented,
    }


def main(argv: list[str]) -> None:
    root = Path(argv[0]) if argv else Path(__file__).resolve().parents[1]
    for key, value in measure(root).items():
        print(f"{key}: {value}")


if __name__ == "__main__":
    main(sys.argv[1:])
