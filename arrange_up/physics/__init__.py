"""The simulated world: the only code that imports pymunk. Place, push (a clipped PD controller) and
pick on a fresh space, run until rest."""

from arrange_up.physics.simulation import *  # noqa: F403  (the public names of the former module arrange_up.physics)
