"""Build hook: ship the Snakemake workflow inside the wheel (issue 13).

The product definition keeps ``Snakefile``, ``workflow/`` and ``data/`` at the top of the repository.
``build_py`` copies them into the built package as ``microimpact/_workflow/`` (``Snakefile``,
``workflow/``, ``data/``), where ``microimpact workflow`` finds them in an installed wheel. An
editable install (``pip install -e``) runs the repository's own Snakefile instead, so there is
one copy of each file in the repository. Everything else is declared in pyproject.toml.
"""

import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
#: repository path -> path inside the package directory of the build
WORKFLOW_FILES = {
    "Snakefile": "_workflow/Snakefile",
    "workflow": "_workflow/workflow",
    "data/synthetic_microspheres.csv": "_workflow/data/synthetic_microspheres.csv",
    "data/kharaz2001_oblique.csv": "_workflow/data/kharaz2001_oblique.csv",
    "data/README.md": "_workflow/data/README.md",
}


class BuildPyWithWorkflow(build_py):
    """build_py, then the workflow files into ``<build>/microimpact/_workflow``."""

    def run(self):
        super().run()
        if getattr(self, "editable_mode", False):
            return  # an editable install runs the repository's Snakefile
        package = Path(self.build_lib) / "microimpact"
        for source, target in WORKFLOW_FILES.items():
            src, dst = ROOT / source, package / target
            if not src.exists():
                raise FileNotFoundError(f"the workflow file {source} is missing from the source tree")
            dst.parent.mkdir(parents=True, exist_ok=True)
            if src.is_dir():
                shutil.copytree(src, dst, dirs_exist_ok=True, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
            else:
                shutil.copy2(src, dst)


setup(cmdclass={"build_py": BuildPyWithWorkflow})
