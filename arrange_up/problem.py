"""Former import path, kept so existing imports work: see :mod:`arrange_up.model.problem`."""

from arrange_up.model.problem import *  # noqa: F403
