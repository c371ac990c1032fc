"""The former module of the fixture repair, now :mod:`arrange_up.repair`: its public names,
re-exported for existing imports."""

from arrange_up.repair import *  # noqa: F403
from arrange_up.repair import __all__  # noqa: F401
