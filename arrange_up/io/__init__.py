"""Reading and writing problems and plans: the YAML format (:mod:`.yaml_problem`), PDDL
(:mod:`.pddl`), plan files (:mod:`.planfile`), the shape catalogue, the shipped problems
(:mod:`.domains`), generated problem files (:mod:`.generate`) and the shipped folders
(:mod:`.resources`); the checks both problem readers share are :mod:`.validation`."""
