"""Sphinx configuration of robodyn's API reference (``make docs``; docs/api/index.rst).

Every public module of robodyn (no path part starting with ``_``) gets one page, written by
autosummary from the package itself, so a new module appears without editing this folder.
The docstrings are Google style (napoleon). The build runs with warnings as errors
(``sphinx-build -W``); tests/integration/test_docs.py runs it.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))
os.environ.setdefault("MPLBACKEND", "Agg")

project = "robodyn"
author = "the robodyn authors"
extensions = ["sphinx.ext.autodoc", "sphinx.ext.autosummary", "sphinx.ext.napoleon"]
autosummary_generate = True
autosummary_imported_members = False
# Each name once, on the page of the module that defines it (a package's __all__ re-exports
# are not documented again).
autodoc_default_options = {"members": True, "show-inheritance": True, "ignore-module-all": True}
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_preserve_defaults = True
napoleon_google_docstring = True
napoleon_numpy_docstring = False
napoleon_use_rtype = False
# An ``Attributes:`` section as fields of its class (not a second description of each attribute).
napoleon_use_ivar = True
templates_path = ["_templates"]
exclude_patterns = ["_build", "generated/*.rst.tmp"]
html_theme = "alabaster"
html_title = "robodyn API reference"
