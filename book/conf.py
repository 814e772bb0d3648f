"""Sphinx configuration of the book: every chapter notebook executed from scratch, offline.

Math is rendered by a local copy of MathJax 3 (from the pinned
``django-static-mathjax`` package, which ships its files), copied into
``_static/mathjax`` after the build, so the book needs no network.
"""

import importlib.util
import shutil
from pathlib import Path

from quadlib.progress import switch_off

switch_off()  # the executed chapters store no progress bars

project = "State estimation for drones"
author = "quadlib authors"
copyright = "2026, quadlib authors"

extensions = ["myst_nb", "sphinx.ext.mathjax"]
exclude_patterns = ["_build", "**.ipynb_checkpoints"]

myst_enable_extensions = ["dollarmath", "amsmath"]
nb_execution_mode = "force"
nb_execution_timeout = 300
nb_execution_raise_on_error = True
nb_execution_show_tb = True
nb_merge_streams = True
nb_ipywidgets_js = {}  # no widget scripts from a CDN: slider cells show no output in the book
nb_code_prompt_show = "Show the solution"  # the only cells the book folds are the exercises' solutions
nb_code_prompt_hide = "Hide the solution"

html_theme = "sphinx_book_theme"
html_title = project
html_theme_options = {
    "show_toc_level": 2,
    "use_download_button": False,  # it would hand out the instructor's notebook: students use the student edition
    "home_page_in_toc": True,
}
html_last_updated_fmt = None

_spec = importlib.util.find_spec("mathjax")
if _spec is None or not _spec.submodule_search_locations:
    raise RuntimeError("MathJax not found: install the pinned django-static-mathjax from environment.txt")
MATHJAX_ES5 = Path(list(_spec.submodule_search_locations)[0]) / "static" / "mathjax" / "es5"
mathjax_path = "mathjax/tex-chtml.js"  # relative to _static


def _copy_mathjax(app, exception):
    if exception is None and app.builder.format == "html":
        shutil.copytree(MATHJAX_ES5, Path(app.outdir) / "_static" / "mathjax", dirs_exist_ok=True)


def setup(app):
    app.connect("build-finished", _copy_mathjax)
