"""microimpact: contact and impact of microspheres with smooth, flat surfaces.

Implements the 3-D model of Cheng, Brach & Dunn (2002), Aerosol Sci. Technol. 36:1081-1093,
doi:10.1080/02786820290092221, with a fast compiled engine, a scipy reference solver, fits of the
damping coefficients, sensitivity sweeps and a Snakemake report.
"""

from importlib.metadata import PackageNotFoundError, version

from microimpact import presets
from microimpact.model.kinematics import ImpactResult
from microimpact.model.contact import Contact

try:
    __version__ = version("microimpact")
except PackageNotFoundError:  # pragma: no cover - running from a source tree without install
    __version__ = "0+unknown"

__all__ = ["Contact", "ImpactResult", "presets", "simulate_impact", "simulate_many", "__version__"]


def __getattr__(name):
    """The solvers are imported on first use (PEP 562): ``import microimpact.report`` compiles nothing."""
    if name in ("simulate_impact", "simulate_many"):
        from microimpact.solvers import impact

        return getattr(impact, name)
    raise AttributeError(f"module 'microimpact' has no attribute {name!r}")
