"""Sphinx configuration of the microimpact documentation site.

Build (the ``docs`` extra): ``python -m sphinx -W --keep-going -b html docs docs/_build/html``.
The API reference is generated from the docstrings (numpydoc), and the gallery scripts in
``docs/examples/`` are executed by sphinx-gallery on every build; CI builds with warnings as
errors. Nothing here reaches the network (no intersphinx), so the build runs offline.
"""

from __future__ import annotations

import os
import re
from importlib.metadata import version as _version

os.environ.setdefault("MPLBACKEND", "Agg")

def _packages() -> list[str]:
    """microimpact and its subpackages: their pages list their names, whose modules document them."""
    import pkgutil

    import microimpact

    return ["microimpact"] + [f"microimpact.{m.name}" for m in pkgutil.iter_modules(microimpact.__path__)
                              if m.ispkg and not m.name.startswith("_")]


def _public(package: str) -> list[str]:
    """The package's public names as paths, relative to it, to the modules that define them."""
    import importlib
    import pkgutil

    module = importlib.import_module(package)
    homes = {}
    for sub in pkgutil.walk_packages(module.__path__, f"{package}."):
        if not any(part.startswith("_") for part in sub.name.split(".")):
            for name in getattr(importlib.import_module(sub.name), "__all__", []):
                homes.setdefault(name, f"{sub.name}.{name}")
    # relative to the package: autosummary refuses items that repeat the current module's name
    return [homes.get(name, f"{package}.{name}").removeprefix(f"{package}.")
            for name in getattr(module, "__all__", []) if not name.startswith("_")]


project = "microimpact"
author = "the microimpact developers"
copyright = "2026, the microimpact developers"  # noqa: A001 - Sphinx's name
release = _version("microimpact")
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "**.ipynb_checkpoints", "examples/README.rst"]
templates_path = ["_templates"]

# the reference: one page per public name, from each module's __all__
autosummary_generate = True
autosummary_ignore_module_all = False
autosummary_imported_members = False
autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_typehints = "none"  # numpydoc's Parameters sections carry the types
autosummary_context = {"packages": _packages(), "package_members": {p: _public(p) for p in _packages()}}
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]

sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"/plot_",
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "abort_on_example_error": True,
}

_LITERAL = re.compile(r"(``.*?``)")


def _escape_bars(app, what, name, obj, options, lines):
    """The docstrings write magnitudes as in plain-text physics, ``|F_n|``; reStructuredText would
    read ``|F_n|`` as a substitution. Escape the bars outside literals and grid tables."""
    for i, line in enumerate(lines):
        stripped = line.strip()
        if "|" in line and not (stripped.startswith(("|", "+")) and stripped.endswith(("|", "+"))):
            parts = _LITERAL.split(line)
            lines[i] = "".join(p if p.startswith("``") else p.replace("|", r"\|") for p in parts)


def setup(app):
    app.connect("autodoc-process-docstring", _escape_bars, priority=400)
    # data/README.md (included as the data-format page) shows its example CSV in a ```csv block,
    # which Pygments has no lexer for: plain text
    from pygments.lexers.special import TextLexer
    from sphinx.highlighting import lexers

    lexers["csv"] = TextLexer()


html_theme = "pydata_sphinx_theme"
html_title = f"microimpact {release}"
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_static_path: list[str] = []
