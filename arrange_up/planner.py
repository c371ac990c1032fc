"""Former import path, kept so existing imports work: see :mod:`arrange_up.planning.planner`."""

from arrange_up.planning.planner import *  # noqa: F403
