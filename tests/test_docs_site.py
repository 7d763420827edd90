"""The documentation site's sources (docs/conf.py, docs/api.rst, docs/examples/) stay complete as
the package grows; CI builds the site itself with warnings as errors (.ci/run)."""

from __future__ import annotations

import pkgutil
import re
from pathlib import Path

import microimpact

DOCS = Path(__file__).resolve().parents[1] / "docs"


def public_modules() -> set[str]:
    return {m.name for m in pkgutil.walk_packages(microimpact.__path__, "microimpact.")
            if not any(part.startswith("_") for part in m.name.split("."))} | {"microimpact"}


def test_the_api_reference_lists_every_public_module():
    """A module missing from docs/api.rst would have no page: its names would be undocumented."""
    listed = set(re.findall(r"^   (microimpact[\w.]*)$", (DOCS / "api.rst").read_text(), flags=re.M))
    assert listed == public_modules(), (public_modules() - listed, listed - public_modules())


def test_every_page_and_example_is_reachable():
    """Each guide page is in a toctree of docs/index.md (Sphinx warns otherwise, and the build
    treats that as an error; this names the page without a build), and each gallery script is
    one sphinx-gallery runs (its name starts with plot_) and has a title in its docstring."""
    index = (DOCS / "index.md").read_text()
    for page in sorted(DOCS.glob("guide/*.md")):
        assert f"guide/{page.stem}\n" in index, page.name
    examples = sorted((DOCS / "examples").glob("*.py"))
    assert len(examples) >= 3
    for script in examples:
        assert script.name.startswith("plot_"), script.name
        title = script.read_text().split('"""')[1].strip().splitlines()
        assert len(title) >= 2 and set(title[1]) == {"="}, script.name
