"""Units of length and angle.

Internally arrange-up always works in **inches** and **radians** (the thesis's units; the physics
is tuned for inches). A problem file may use other units; they are converted once, at load time,
and the problem keeps its :class:`Units` so results can be written back in the user's units.

Densities are areal (mass per square length unit) and convert with the square of the length
factor; friction coefficients are dimensionless.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

#: Inches per one of each accepted length unit.
LENGTH_UNITS: dict[str, float] = {"in": 1.0, "cm": 1.0 / 2.54, "mm": 1.0 / 25.4, "m": 100.0 / 2.54}
#: Radians per one of each accepted angle unit.
ANGLE_UNITS: dict[str, float] = {"deg": math.pi / 180.0, "rad": 1.0}


@dataclass(frozen=True)
class Units:
    """The units a problem file is written in (``units: {length: in, angle: deg}``)."""

    length: str = "in"
    angle: str = "deg"

    def __post_init__(self) -> None:
        if self.length not in LENGTH_UNITS:
            raise ValueError(
                f"unknown length unit {self.length!r}; expected one of {', '.join(LENGTH_UNITS)}"
            )
        if self.angle not in ANGLE_UNITS:
            raise ValueError(
                f"unknown angle unit {self.angle!r}; expected one of {', '.join(ANGLE_UNITS)}"
            )

    @property
    def length_factor(self) -> float:
        """Inches per user length unit."""
        return LENGTH_UNITS[self.length]

    @property
    def angle_factor(self) -> float:
        """Radians per user angle unit."""
        return ANGLE_UNITS[self.angle]

    # -- user units -> internal (inches, radians) -------------------------------------------
    def length_in(self, value: float) -> float:
        return float(value) * self.length_factor

    def angle_in(self, value: float) -> float:
        return float(value) * self.angle_factor

    def pose_in(self, pose: tuple[float, float, float]) -> tuple[float, float, float]:
        """Convert a pose or a pose half-width ``(x, y, theta)`` to inches and radians."""
        return (self.length_in(pose[0]), self.length_in(pose[1]), self.angle_in(pose[2]))

    def density_in(self, value: float) -> float:
        """Mass per square user length unit -> mass per square inch."""
        return float(value) / self.length_factor**2

    # -- internal -> user units ---------------------------------------------------------------
    def length_out(self, value: float) -> float:
        return float(value) / self.length_factor

    def angle_out(self, value: float) -> float:
        return float(value) / self.angle_factor

    def pose_out(self, pose: tuple[float, float, float]) -> tuple[float, float, float]:
        """Convert an internal pose back to the user's units."""
        return (self.length_out(pose[0]), self.length_out(pose[1]), self.angle_out(pose[2]))

    def density_out(self, value: float) -> float:
        return float(value) * self.length_factor**2
