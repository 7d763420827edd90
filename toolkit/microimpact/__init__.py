"""microimpact: contact and impact of microspheres with smooth, flat surfaces.

Implements the 3-D model of Cheng, Brach & Dunn (2002), Aerosol Sci. Technol. 36:1081-1093,
doi:10.1080/02786820290092221, with a fast compiled engine, a scipy reference solver, fits of the
damping coefficients, sensitivity sweeps and a Snakemake report.
"""

import sys


from microimpact._lazy import lazy_exports as _lazy_exports

__all__ = ["Contact", "ImpactResult", "presets", "simulate_impact", "simulate_many", "__version__"]


def _announce_numba_compiles() -> None:
    """Print one stderr line when numba starts compiling a microimpact function (a cold cache).

    Registered as numba's ``numba_extensions``/``init`` entry point (pyproject.toml), which numba
    runs before its first compilation or cache look-up in a process. Numba raises the
    ``numba:compile`` event only on a cache miss, so the notice appears on the first call after
    installing (or after a change of the compiled code), never when the compiled solvers are
    loaded from numba's cache. Other packages' numba functions are ignored.
    """
    from numba.core import event

    class _FirstCompileNotice(event.Listener):
        done = False

        def on_start(self, ev):
            dispatcher = (ev.data or {}).get("dispatcher")
            module = getattr(getattr(dispatcher, "py_func", None), "__module__", "") or ""
            if not self.done and module.startswith("microimpact."):
                self.done = True
                # the range in the message comes from docs/compile-times.json
                print("microimpact: compiling the solvers with numba (first run only, 10-25 s per "
                      "solver; cached for later runs)", file=sys.stderr, flush=True)

        def on_end(self, ev):
            pass

    event.register("numba:compile", _FirstCompileNotice())


#: public names imported on first use -> their module, relative to the package
_LAZY = {"Contact": "model.contact", "ImpactResult": "model.kinematics", "simulate_impact": "solvers.impact",
         "simulate_many": "solvers.impact"}
#: the subpackages and modules, importable as attributes (``microimpact.io``)
_SUBMODULES = ("analysis", "cli", "dynamics", "io", "model", "presets", "report", "solvers", "studies")
_lazy_getattr, _lazy_dir = _lazy_exports("microimpact", _LAZY, _SUBMODULES)


def __getattr__(name):
    """Everything is imported on first use (PEP 562): ``import microimpact`` loads no numpy, so a
    Ctrl-C right after ``microimpact`` starts reaches the command line's handler (one line, status
    130) and not an import of numpy; ``import microimpact.report`` compiles nothing."""
    if name == "__version__":
        from importlib.metadata import PackageNotFoundError, version

        try:
            return version("microimpact")
        except PackageNotFoundError:  # pragma: no cover - a source tree without install
            return "0+unknown"
    return _lazy_getattr(name)


def __dir__():
    """The public names, also those imported on first use (for ``dir()`` and tab completion)."""
    return sorted({*_lazy_dir(), "__version__"})
