"""Former import path, kept so existing imports work: see :mod:`arrange_up.up.compile`."""

from arrange_up.up.compile import *  # noqa: F403
