"""Former import path, kept so existing imports work: see :mod:`arrange_up.evaluation`."""

from arrange_up.evaluation import *  # noqa: F403
