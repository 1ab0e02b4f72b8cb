"""Sphinx configuration of the documentation site.

    sphinx-build -W --keep-going -b html docs OUT        (needs the ``docs`` extra)

The pages are the Markdown files of docs/, read by myst-parser as they are (they stay readable on
GitHub); the API reference (docs/api/) is autodoc with numpydoc; the gallery is sphinx-gallery running
the recipes of examples/gallery/ into docs/gallery/ (generated, not committed). The package is imported
as installed (``pip install -e .``), so the reference documents the code the recipes run.
"""
from __future__ import annotations

import sys
from pathlib import Path

import restitution

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))  # recipe_order (the gallery's order) and units_in_docs (a local extension)

project = "restitution"
author = "the restitution authors"
copyright = "the restitution authors, MIT License"
release = version = restitution.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "units_in_docs",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
# mutation_survivors.txt is data the testing page describes, not a page; _build: a build inside docs/.
exclude_patterns = ["_build", "mutation_survivors.txt"]
# Option names such as --fmu stay as typed: no "--" turned into a dash, no curly quotes.
smartquotes = False
# furo: the content column narrows with the window, and a code block wider than the column scrolls
# sideways inside it (its pre is overflow: auto) instead of running past the column's edge, as it did
# with alabaster's fixed 940 px body. tests/docs/test_docs_site.py measures that in a headless
# chromium at 1280 px.
html_theme = "furo"
html_title = f"restitution {release}"
html_short_title = "restitution"
# _static/code_blocks.css: a long line's scrollbar is drawn always, not only while scrolling
html_static_path = ["_static"]
html_css_files = ["code_blocks.css"]

# --- Markdown pages (myst-parser) --------------------------------------------------------------
# The pages link to sections of each other as GitHub does ("calibration.md#from-python",
# "#limits"): GitHub's anchors are its slugs of the headings, which myst makes for headings down to
# this level (the pages link to ## and ### headings).
myst_heading_anchors = 4
# Equations are Unicode text in the pages; no $...$ or other extension is needed.
myst_enable_extensions = []

# --- API reference (autodoc + numpydoc) -------------------------------------------------------
autodoc_member_order = "bysource"
# The docstrings say what each argument is and its unit in words; the signature keeps the annotations
# as written (strings such as "Real" for ImpactResult's fields, "float | None").
autodoc_typehints = "signature"
# ImpactResult's fields are annotated Real (a float, or an array of floats for an array of impacts)
# or Flag (a bool, or an array of bools): shown as written, not as the alias's target, object.
autodoc_type_aliases = {"Real": "Real", "Flag": "Flag"}
autosummary_generate = False  # the API pages list their objects themselves: nothing is generated
# numpydoc renders Parameters/Returns sections where a docstring has them and leaves the others' prose
# alone. Most of the package's docstrings are prose (argument, meaning, unit in brackets), not numpydoc
# sections, so no validation check is run; the class pages list their members themselves (autodoc's
# :members:), not numpydoc's generated tables, which would list each field twice.
numpydoc_validation_checks: set[str] = set()
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

# --- Gallery (sphinx-gallery) --------------------------------------------------------------------
sphinx_gallery_conf = {
    "examples_dirs": "../examples/gallery",
    "gallery_dirs": "gallery",
    # every recipe runs, not only plot_*.py (the FMU and custom-material recipes print, not draw)
    "filename_pattern": r".*\.py$",
    "within_subsection_order": "recipe_order.RecipeOrder",
    # a recipe that fails fails the build: the gallery shows only code that ran
    "abort_on_example_error": True,
    "download_all_examples": False,
    "show_signature": False,
    "remove_config_comments": True,
    "reset_modules": ("matplotlib",),
    # no code-to-API back-references: the API pages are written by hand (docs/api/)
    "backreferences_dir": None,
    "doc_module": (),
}
