"""matplotlib as the figures use it: drawn off screen, written to files.

Importing this module imports matplotlib, which is slow (docs/design/figures.md gives the
figure and its command): the command line imports the figure modules only in the commands that
draw.
"""

from __future__ import annotations

from pathlib import Path
from types import ModuleType
from typing import Any

import matplotlib
import matplotlib.pyplot

__all__ = ["FIGURE_SUFFIXES", "figure_format", "pyplot", "save_figure"]

#: Picture formats a figure is saved in, by the suffix of its file.
FIGURE_SUFFIXES: dict[str, str] = {".png": "png", ".svg": "svg", ".pdf": "pdf"}


def pyplot() -> ModuleType:
    """``matplotlib.pyplot`` with the non-interactive Agg backend selected (no window is ever
    opened; figures are saved and closed by their callers)."""
    matplotlib.use("Agg", force=False)
    return matplotlib.pyplot


def figure_format(path: str | Path) -> str:
    """The format a figure saved at ``path`` is written in, named by its suffix (case
    ignored): a file called ``x.svg`` holds an SVG. Raises ``ValueError`` for other suffixes."""
    suffix = Path(path).suffix.lower()
    if suffix not in FIGURE_SUFFIXES:
        raise ValueError(
            f"{path}: cannot draw a picture in format {suffix or '(no suffix)'!r}; expected a "
            f"file name ending in {', '.join(FIGURE_SUFFIXES)}"
        )
    return FIGURE_SUFFIXES[suffix]


def save_figure(fig: Any, output: str | Path, *, dpi: int, **options: Any) -> Path:
    """Write ``fig`` at ``output``, its folders made first, in the format its suffix names
    (:func:`figure_format`); ``options`` go to ``savefig``. Returns the path. The caller
    closes the figure."""
    output = Path(output)
    output.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(output, dpi=dpi, format=figure_format(output), **options)
    return output
