"""microimpact: contact and impact of microspheres with smooth, flat surfaces.

Implements the 3-D model of Cheng, Brach & Dunn (2002), Aerosol Sci. Technol. 36:1081-1093,
doi:10.1080/02786820290092221, with a fast compiled engine, a scipy reference solver, fits of the
damping coefficients, sensitivity sweeps and a Snakemake report.
"""

from importlib.metadata import PackageNotFoundError, version

from microimpact.model.kinematics import ImpactResult
from microimpact.model.contact import Contact

try:
    __version__ = version("microimpact")
except PackageNotFoundError:  # pragma: no cover - running from a source tree without install
    __version__ = "0+unknown"

__all__ = ["Contact", "ImpactResult", "presets", "simulate_impact", "simulate_many", "__version__"]


def _announce_numba_compiles() -> None:
    """Print one stderr line when numba starts compiling a microimpact function (a cold cache).

    Registered as numba's ``numba_extensions``/``init`` entry point (pyproject.toml), which numba
    runs before its first compilation or cache look-up in a process. Numba raises the
    ``numba:compile`` event only on a cache miss, so the notice appears on the first call after
    installing (or after a change of the compiled code), never when the compiled solvers are
    loaded from numba's cache. Other packages' numba functions are ignored.
    """
    import sys

    from numba.core import event

    class _FirstCompileNotice(event.Listener):
        done = False

        def on_start(self, ev):
            dispatcher = (ev.data or {}).get("dispatcher")
            module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
            if not self.done and module.startswith("microimpact."):
                self.done = True
                print("microimpact: compiling the solvers with numba (first run only, about 20 s; "
                      "cached for later runs)", file=sys.stderr, flush=True)

        def on_end(self, ev):
            pass

    event.register("numba:compile", _FirstCompileNotice())


def __getattr__(name):
    """The solvers and the presets are imported on first use (PEP 562): ``import microimpact`` loads
    numpy only (no numba, xarray or pandas), and ``import microimpact.report`` compiles nothing."""
    if name in ("simulate_impact", "simulate_many"):
        from microimpact.solvers import impact

        return getattr(impact, name)
    if name == "presets":
        import importlib

        return importlib.import_module("microimpact.presets")
    raise AttributeError(f"module 'microimpact' has no attribute {name!r}")
