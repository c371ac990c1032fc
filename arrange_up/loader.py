"""Former import path, kept so existing imports work: see :mod:`arrange_up.io.yaml_problem`."""

from arrange_up.io.yaml_problem import *  # noqa: F403
