"""Sphinx configuration of the course website (built by `contactfem site`).

`contactfem site` stages a source folder (the notebooks of lectures/, this folder, and
the generated pages: gallery, equation index, API reference, benchmarks) and runs
Sphinx on it with warnings as errors. Notebooks are executed by MyST-NB in the fast
preset and cached (jupyter-cache), so a second build only re-runs a notebook whose
code changed; the builder empties the cache when the package's code changes.
Equations are typeset by MathJax 3 served from the site itself (_static/mathjax):
no network at build or read time.
"""

import os

project = "contactfem: impact-contact with friction"
author = "contactfem authors"
copyright = "contactfem authors (MIT licence)"

extensions = ["myst_nb", "sphinx.ext.autodoc", "sphinx.ext.mathjax"]

source_suffix = {".md": "myst-nb", ".ipynb": "myst-nb"}
exclude_patterns = ["_build", "_static", "**.ipynb_checkpoints"]
root_doc = "index"

# -- notebooks: executed (fast preset, set by the builder), cached, failures are errors
nb_execution_mode = os.environ.get("CONTACTFEM_SITE_EXECUTE", "cache")
nb_execution_cache_path = os.environ.get("CONTACTFEM_SITE_CACHE", "")
nb_execution_timeout = 300
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_merge_streams = True
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_dmath_double_inline = True  # $$...$$ inside a paragraph or list item, as Jupyter shows it
myst_heading_anchors = 3

# -- API reference from the docstrings
autodoc_default_options = {"members": True, "member-order": "bysource", "ignore-module-all": True}
autodoc_typehints = "none"
add_module_names = False
nitpicky = True  # a reference that does not resolve (e.g. in the equation index) is an error
# (type names in signatures outside contactfem, e.g. numpy's, are not documented here)
nitpick_ignore_regex = [("py:class", r"(?!contactfem\.).*")]


def docstring_as_written(app, what, name, obj, options, lines):
    """The docstrings are plain text written for help() and a reader of the paper
    (t_N, |t_T|, indented formulas), not reStructuredText: show them as written."""
    if lines:
        lines[:] = [".. code-block:: text", ""] + ["    " + ln for ln in lines] + [""]


def setup(app):
    app.connect("autodoc-process-docstring", docstring_as_written)


# -- MathJax 3 from the site itself (copied from the django-static-mathjax package)
html_static_path = ["_static"]
mathjax_path = "mathjax/tex-chtml.js"
# Sphinx writes math as \( \) and \[ \]; a '$$' left in the page is a bug the browser check sees
# and an undefined macro is an error (MathJax's default would print it in red and go on)
mathjax3_config = {
    "tex": {"inlineMath": [["\\(", "\\)"]], "displayMath": [["\\[", "\\]"]], "packages": {"[-]": ["noundefined"]}}
}

html_theme = "alabaster"
html_title = "contactfem course"
html_theme_options = {
    "description": "Large-deformation impact-contact with friction (Wriggers, Vu Van & Stein 1990) on scikit-fem",
    "page_width": "1180px",
    "sidebar_width": "260px",
}
html_sidebars = {"**": ["about.html", "navigation.html", "relations.html", "searchbox.html"]}
html_show_sourcelink = False
