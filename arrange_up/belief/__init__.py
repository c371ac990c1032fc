"""Belief states: particles and factored intervals, angle frames, domination and goal tests."""

from arrange_up.belief.states import *  # noqa: F403  (the public names of the former module arrange_up.belief)
