"""arrange-up: conformant planning for robot tabletop manipulation.

Importing this package is cheap: heavy libraries (unified-planning, pymunk, matplotlib) are
imported only by the modules that need them.
"""

from __future__ import annotations

__version__ = "0.1.0"
