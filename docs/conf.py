"""Sphinx configuration: the API reference (autodoc + napoleon, numpy-style docstrings) and
the user guide (Markdown through myst-parser). Build: see README's test command."""

from __future__ import annotations

import coulomb

project = "coulomb"
author = "the coulomb authors"
copyright = "the coulomb authors"
release = coulomb.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "myst_parser",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build"]
myst_enable_extensions = ["dollarmath", "deflist"]
myst_heading_anchors = 3

napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False
# Attributes sections as :ivar: fields: the result dataclasses' fields would otherwise be
# described twice (by napoleon and by autodoc's members)
napoleon_use_ivar = True
# shape words in types ("ndarray, shape (nc, dim)") are not objects: without this, "nc" would
# be linked to whichever problem class of coulomb.io has an attribute nc (an ambiguous target)
napoleon_preprocess_types = True
napoleon_type_aliases = {"nc": "*nc*"}
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "show-inheritance": True}

html_theme = "alabaster"
html_title = f"coulomb {release}"
