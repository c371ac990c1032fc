"""The API reference (docs/api, Sphinx) covers every module of the package.

Each page lists its room's modules with ``.. automodule::``; a module added to the package
must be added to its room's page. Left out: ``__main__`` and the modules that only keep a
former import path working (their whole body is a ``from ... import *``), whose names the
reference documents where they live now. Building the reference is CI's job (``.ci/run``:
``sphinx-build -W``), not this test's.
"""

from __future__ import annotations

import re
from pathlib import Path

from doc_runner import REPOSITORY

PACKAGE = REPOSITORY / "arrange_up"
PAGES = REPOSITORY / "docs" / "api"
AUTOMODULE = re.compile(r"^\.\. automodule:: (\S+)$", re.MULTILINE)


def _module(path: Path) -> str:
    parts = path.relative_to(REPOSITORY).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _is_former_path(path: Path) -> bool:
    code = [
        line
        for line in path.read_text(encoding="utf-8").splitlines()
        if line.startswith(("from ", "import "))
    ]
    return bool(code) and all(" import *" in line or "__all__" in line for line in code)


def test_every_module_is_in_the_reference() -> None:
    listed = {m for page in PAGES.glob("*.rst") for m in AUTOMODULE.findall(page.read_text())}
    modules = {
        _module(path)
        for path in PACKAGE.rglob("*.py")
        if path.name != "__main__.py" and not _is_former_path(path)
    }
    missing = sorted(modules - listed - {"arrange_up"})
    assert not missing, f"add these modules to their room's page in docs/api/: {missing}"
    assert listed <= modules | {"arrange_up"}, sorted(listed - modules)


def test_every_page_is_in_the_table_of_contents() -> None:
    index = (PAGES / "index.rst").read_text(encoding="utf-8")
    for page in PAGES.glob("*.rst"):
        if page.stem != "index":
            assert re.search(rf"^   {page.stem}$", index, re.MULTILINE), page.name
