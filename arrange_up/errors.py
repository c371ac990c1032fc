"""Former import path, kept so existing imports work: see :mod:`arrange_up.model.errors`."""

from arrange_up.model.errors import *  # noqa: F403
