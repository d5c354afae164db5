"""Sphinx configuration of the fem_twin documentation.

Build: ``python -m sphinx -W -b html docs docs/_build/html`` (``pip install ".[docs]"``);
``FEM_TWIN_DOCS_GALLERY=0`` skips running the examples (the gallery then has no figures).
"""

import os
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE / "_ext"))

import fem_twin  # noqa: E402

project = "fem_twin"
author = "fem_twin developers"
copyright = "2026, fem_twin developers (BSD-3-Clause)"
release = version = fem_twin.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "fem_twin_docs",                 # the generated references (case file, CLI)
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
exclude_patterns = ["_build", "reference/_generated", "auto_examples/*.ipynb", "auto_examples/*.py",
                    "auto_examples/*.zip", "auto_examples/*.json", "auto_examples/*.md5"]
myst_enable_extensions = ["dollarmath", "colon_fence", "deflist"]
myst_heading_anchors = 3

autosummary_generate = True
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": True,
                           "ignore-module-all": True}
suppress_warnings = ["config.cache"]      # sphinx_gallery_conf holds a function (reset_argv)
autodoc_typehints = "none"
numpydoc_show_class_members = False
numpydoc_validation_checks = set()
numpydoc_xref_param_type = False

html_theme = "pydata_sphinx_theme"
html_title = "fem_twin"
html_static_path = ["_static"]
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "footer_start": ["copyright"],
}
html_sidebars = {"index": [], "getting_started": [], "tutorial": []}

SHARED = ROOT.parent / "shared" / "topographies"
GALLERY_OUT = Path(os.environ.get("FEM_TWIN_DOCS_OUT")
                   or tempfile.mkdtemp(prefix="fem_twin_gallery_"))


def example_argv(gallery_conf, script_vars):
    """Each example at its --quick size, writing into a scratch folder."""
    stem = Path(script_vars["src_file"]).stem
    target = GALLERY_OUT / (f"{stem}.png" if stem[:2] in ("01", "02") else stem)
    return [str(target), "--quick"]


# examples that read ../shared/topographies are shown but not run when it is absent
NEEDS_SHARED = [] if SHARED.is_dir() else sorted(
    path.stem[:2] for path in (ROOT / "examples").glob("[0-9][0-9]_*.py")
    if '"shared" / "topographies"' in path.read_text(encoding="utf-8"))
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/(?!" + "|".join(NEEDS_SHARED or ["$^"]) + r")\d\d_",
    "ignore_pattern": r"__init__\.py",
    "reset_argv": example_argv,
    "plot_gallery": os.environ.get("FEM_TWIN_DOCS_GALLERY", "1") != "0",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": True,
    "only_warn_on_example_error": False,
    "matplotlib_animations": False,
}
