"""Sphinx configuration of volanim's documentation site (``make docs`` -> ``docs/_build/html``).

Why Sphinx: the libraries our users know (scikit-image, pyvista, napari) build their sites with it, and it
has the three things this site needs from one tool: MyST for the Markdown pages (the tutorials are the
README's sections, still plain Markdown that GitHub shows), autodoc + numpydoc for the API reference from
the docstrings, and sphinx-gallery for examples that are run at build time to make the pictures beside
them. The build is strict (``-W --keep-going -n``): a warning, a broken internal link or a reference to a
missing API name fails it.

Generated at build time, never typed (``_ext/volanim_docs.py``): the command-line reference from the
``volanim`` parsers, and the studio's shortcuts from the table F1 shows.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))

project = "volanim"
author = "the volanim developers"
copyright = "2026, the volanim developers"  # noqa: A001 -- Sphinx's name
from volanim_core import __version__ as release  # noqa: E402

version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "numpydoc",
    "sphinx_gallery.gen_gallery",
    "volanim_docs",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "examples/README.txt", "auto_examples/*.ipynb", "auto_examples/*.py",
                    "auto_examples/*.zip", "auto_examples/*.md5", "auto_examples/*.codeobj.json"]

myst_heading_anchors = 4  # [text](page.md#a-heading) resolves, and a wrong one is a warning
myst_enable_extensions = ["colon_fence"]

nitpicky = True  # a reference to a missing API name fails the build ...
nitpick_ignore_regex = [  # ... except names outside volanim (no network here for intersphinx inventories)
    (r"py:.*", r"(np|numpy|pv|pyvista|vtk|dask|zarr|pathlib|collections|typing|os)\..*"),
    (r"py:.*", r"(ndarray|array_like|array-like|str|int|float|bool|dict|list|tuple|None|callable|Path|"
               r"optional|default|object|bytes|iterable|sequence|Sequence|Callable|Iterable|Iterator|any)"),
    (r"py:.*", r".*(of|or|shape|ndarray).*"),
    (r"py:class", r".*[\[\]'].*"),  # a dataclass field's annotation, as autodoc quotes it in a signature
]

autodoc_member_order = "bysource"
autodoc_typehints = "none"  # numpydoc's Parameters sections say the types
numpydoc_show_class_members = False
numpydoc_validation_checks: set[str] = set()

sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "show_memory": False,
    "within_subsection_order": "FileNameSortKey",
}

html_theme = "pydata_sphinx_theme"
html_title = "volanim"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_depth": 2,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": [],
}
html_sidebars = {"index": []}
