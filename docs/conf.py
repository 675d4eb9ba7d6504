"""Sphinx configuration of the tubefsi documentation (``make docs``)."""

import importlib.util
import shutil
from pathlib import Path

import tubefsi

project = "tubefsi"
author = "the tubefsi developers"
copyright = "2026, the tubefsi developers (BSD 3-Clause licence)"
release = version = tubefsi.__version__
extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]
# the gallery: examples/gallery/plot_*.py run during the build; their figures come from that run
sphinx_gallery_conf = {
    "examples_dirs": "../examples/gallery",
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "write_computation_times": False,
}
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3
exclude_patterns = ["_build", "_generated/**/*.csv", "gallery/*.ipynb", "gallery/*.py", "gallery/*.zip"]
numpydoc_show_class_members = False
numpydoc_validation_checks = set()
autodoc_member_order = "bysource"
autodoc_typehints = "none"
html_theme = "alabaster"
html_static_path = []
suppress_warnings = ["myst.header"]

# MathJax is served from the site itself, not from a CDN, so that the math renders offline
# (issue 27): the docs extra's django-static-mathjax ships MathJax 3 as plain files (it needs no
# Django); after the build, _copy_mathjax puts the browser components into _static/mathjax.
# A relative mathjax_path is relative to _static.
mathjax_path = "mathjax/tex-mml-chtml.js"
#: what tex-mml-chtml.js loads on demand: TeX extensions (autoload), fonts, the menu, the
#: accessibility tools; plus MathJax's licence
_MATHJAX_PARTS = ("tex-mml-chtml.js", "input", "output", "ui", "a11y", "sre", "../LICENSE")


def _mathjax_source():
    """The directory of MathJax's browser components (``es5``) in django-static-mathjax."""
    spec = importlib.util.find_spec("mathjax")
    for root in (spec.submodule_search_locations or []) if spec else []:
        es5 = Path(root) / "static" / "mathjax" / "es5"
        if (es5 / mathjax_path.split("/", 1)[1]).is_file():
            return es5
    raise RuntimeError("the docs serve MathJax from the site: install the docs extra "
                       "(pip install '.[docs]', or make docs), which brings django-static-mathjax")


def _copy_mathjax(app, exception):
    if exception is not None or app.builder.format != "html":
        return
    source, target = _mathjax_source(), Path(app.outdir) / "_static" / "mathjax"
    for part in _MATHJAX_PARTS:
        path = (source / part).resolve()
        if path.is_dir():
            shutil.copytree(path, target / part, dirs_exist_ok=True)
        else:
            target.mkdir(parents=True, exist_ok=True)
            shutil.copy2(path, target / path.name)


def setup(app):
    _mathjax_source()            # fail at the start of the build, not after it, when it is missing
    app.connect("build-finished", _copy_mathjax)
