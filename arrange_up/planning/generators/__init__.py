"""The action generators of the planner, one module per kind of action or rule, composed by
:class:`arrange_up.planning.actions.ActionGenerator` (in the manner of pyperplan's one module
per heuristic).

* :mod:`~arrange_up.planning.generators.common`: push directions, resolutions, the options;
* :mod:`~arrange_up.planning.generators.targets`: where the goal wants each part;
* :mod:`~arrange_up.planning.generators.places`: places of parts;
* :mod:`~arrange_up.planning.generators.pushes`: pushes of parts, from
* :mod:`~arrange_up.planning.generators.approach`: where the manipulator stands across,
* :mod:`~arrange_up.planning.generators.distances`: how far it travels, with
* :mod:`~arrange_up.planning.generators.wall_trains`: the goal's trains against walls,
* :mod:`~arrange_up.planning.generators.mating_pushes`: pushes against a relative goal's mate,
* :mod:`~arrange_up.planning.generators.detours`: pushes round obstacles and cut short,
* :mod:`~arrange_up.planning.generators.stall`: the compliant controller's stall and the
  distance solver;
* :mod:`~arrange_up.planning.generators.picks`: picks of fixtures and manipulators.

Places of fences are :mod:`arrange_up.planning.fences`' own.
"""
