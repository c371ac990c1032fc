"""Reading and writing problems and plans: the YAML format, PDDL, plan files, the shape catalogue
and the shipped problems and semantics."""
