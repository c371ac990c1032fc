"""Former import path, kept so existing imports work: see :mod:`arrange_up.evaluation.evaluate`."""

from arrange_up.evaluation.evaluate import *  # noqa: F403
