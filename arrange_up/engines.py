"""Former import path, kept so existing imports work: see :mod:`arrange_up.up.engines`."""

from arrange_up.up.engines import *  # noqa: F403
