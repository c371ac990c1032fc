"""Planning in belief space: the action generators, the heuristics and the planner that runs
:mod:`arrange_up.search` over beliefs."""
