"""Sphinx configuration of arrange-up's API reference, built from the docstrings.

Build it (the ``docs`` extra installs Sphinx; CI builds it with warnings as errors)::

    pip install ".[docs]"
    sphinx-build -W --keep-going -b html docs/api docs/api/_build/html
"""

from __future__ import annotations

import arrange_up

project = "arrange-up"
author = "arrange-up developers"
release = version = arrange_up.__version__

extensions = ["sphinx.ext.autodoc", "sphinx.ext.napoleon", "sphinx.ext.viewcode"]

# Members in source order, as each module's docstring introduces them; type hints go into the
# description, where a long signature stays readable.
autodoc_member_order = "bysource"
autodoc_typehints = "description"
# A module documents what it defines: the re-exports that keep former import paths working
# (``__all__`` lists that name another module's objects) would document an object twice.
autodoc_default_options = {"members": True, "show-inheritance": True, "ignore-module-all": True}
# Docstrings name code with ``double backticks`` and cross-reference with :func:, :class: and
# :mod:; single backticks are an inline literal too (a few docstrings use Markdown's).
default_role = "code"
# References to names outside the package (numpy, pymunk, unified-planning) are not resolved
# without their inventories, which would need the network: no nitpicky warnings for those.
nitpicky = False

exclude_patterns = ["_build"]
html_theme = "alabaster"
html_title = f"arrange-up {release} API reference"
