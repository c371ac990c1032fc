"""matplotlib as the figures use it: drawn off screen, written to files.

Importing this module imports matplotlib, which is slow (docs/design/figures.md gives the
figure and its command): the command line imports the figure modules only in the commands that
draw.
"""

from __future__ import annotations

from types import ModuleType

import matplotlib
import matplotlib.pyplot

__all__ = ["pyplot"]


def pyplot() -> ModuleType:
    """``matplotlib.pyplot`` with the non-interactive Agg backend selected (no window is ever
    opened; figures are saved and closed by their callers)."""
    matplotlib.use("Agg", force=False)
    return matplotlib.pyplot
