"""Public names that load their module on first use (PEP 562), for the packages' ``__init__``."""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Iterable


def lazy_exports(package: str, homes: dict[str, str], modules: Iterable[str] = ()
                 ) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """``(__getattr__, __dir__)`` for a package whose names are imported when first used.

    Parameters
    ----------
    package : str
        The package's name, e.g. ``"microimpact.io"``.
    homes : dict of str to str
        Public name -> the module, relative to ``package``, that defines it.
    modules : iterable of str
        Submodules reachable as attributes (``microimpact.io.files``).

    Returns
    -------
    tuple of callables
        The module-level ``__getattr__`` and ``__dir__``: ``dir()`` and tab completion show every
        public name and submodule, loaded or not, and none of the package's private helpers.

    Examples
    --------
    >>> getattr_, dir_ = lazy_exports("os", {"sep": "path"}, ["path"])
    >>> getattr_("sep") == __import__("os").sep
    True
    >>> {"sep", "path"} <= set(dir_())
    True
    """
    modules = tuple(modules)

    def __getattr__(name: str):
        if name in homes:
            return getattr(importlib.import_module(f"{package}.{homes[name]}"), name)
        if name in modules:
            return importlib.import_module(f"{package}.{name}")
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__() -> list[str]:
        present = vars(sys.modules[package])
        dunders = {n for n in present if n.startswith("__") and n.endswith("__")}
        loaded = {n for n, v in present.items() if not n.startswith("_") and getattr(v, "__name__", "").startswith(
            f"{package}.")}  # submodules imported since
        return sorted(dunders | set(homes) | set(modules) | loaded)

    return __getattr__, __dir__
