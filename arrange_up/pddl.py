"""Former import path, kept so existing imports work: see :mod:`arrange_up.io.pddl`."""

from arrange_up.io.pddl import *  # noqa: F403
