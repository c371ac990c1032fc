"""unified-planning: the problem compiled to a UP problem, action effects resolved by a semantics,
and the engines. The only room that imports unified-planning."""
