"""Former import path, kept so existing imports work: see :mod:`arrange_up.io.domains`."""

from arrange_up.io.domains import *  # noqa: F403
