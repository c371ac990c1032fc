"""The folders arrange-up ships beside its code: ``domains/`` (the shipped problems) and
``semantics/`` (the shape catalogue, the PDDL domain and the CBST models).

A checkout (or an editable install) keeps them next to the package, in the repository's root;
an installed wheel carries them inside the package as ``arrange_up/_shipped/<name>`` (see
``[tool.hatch.build.targets.wheel.force-include]`` in ``pyproject.toml``).
:func:`shipped_dir` finds whichever is present, the wheel's first.

    >>> shipped_dir("semantics/cbst", "CBST models").name
    'cbst'
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["CHECKOUT_DIR", "PACKAGE_DIR", "WHEEL_DIR", "shipped_dir"]

#: The ``arrange_up`` package folder.
PACKAGE_DIR = Path(__file__).resolve().parent.parent
#: Where an installed wheel keeps the shipped folders (``force-include`` in pyproject.toml).
WHEEL_DIR = PACKAGE_DIR / "_shipped"
#: Where a checkout (or an editable install) keeps them: the repository's root.
CHECKOUT_DIR = PACKAGE_DIR.parent


def shipped_dir(name: str, what: str) -> Path:
    """The shipped folder ``name`` (``"domains"``, ``"semantics"``, ``"semantics/cbst"``).

    An installed wheel's ``arrange_up/_shipped/<name>`` wins; otherwise the checkout's
    ``<name>`` next to the package. ``what`` names the folder's contents in the error.

    Raises:
        FileNotFoundError: neither folder exists (a broken installation).
    """
    # WHEEL_DIR and CHECKOUT_DIR are read at each call, so a test can point them elsewhere.
    wheel, checkout = WHEEL_DIR / name, CHECKOUT_DIR / name
    for candidate in (wheel, checkout):
        if candidate.is_dir():
            return candidate
    raise FileNotFoundError(
        f"arrange-up's shipped {what} are missing: looked in "
        f"{wheel} (installed wheel) and {checkout} (checkout)"
    )
