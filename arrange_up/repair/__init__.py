"""Fixture-placement plan repair (thesis ch. 4)."""

from arrange_up.repair.fixture_repair import *  # noqa: F403  (the public names of the former module arrange_up.repair)
