"""Former import path, kept so existing imports work: see :mod:`arrange_up.io.planfile`."""

from arrange_up.io.planfile import *  # noqa: F403
