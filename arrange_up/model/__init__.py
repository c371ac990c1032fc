"""The problem as data: frozen dataclasses for tables, shapes, objects, initial beliefs, goals and
noise (:mod:`.problem`), world states and actions (:mod:`.world`), units (:mod:`.units`) and
diagnostics (:mod:`.errors`). Imports nothing else of arrange-up."""
