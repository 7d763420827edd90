"""Which parameters made a result: the ``contact_*`` and ``parameter_source`` attributes.

Every result Dataset of the toolkit records the contact it was computed with (``contact_<field>``,
SI units; one value per size, as arrays, when a result spans several sphere sizes) and where those
parameters came from, in ``parameter_source``:

- ``"fit: <data file> <sha256>"``: fitted to measurements (:mod:`microimpact.analysis.fitting`);
- ``"preset: <name>"``: a named set of :mod:`microimpact.presets` (the paper's Table 1 rows);
- ``"materials: <pair>"``: a pair of a materials config (:mod:`microimpact.io.materials`);
- ``"config"``: numbers given in a configuration.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import fields
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from microimpact.model.contact import SUB_MODELS, Contact

if TYPE_CHECKING:  # only for annotations: importing xarray would slow the CLI's start-up
    import xarray as xr

__all__ = ["contact_attributes", "stamp_parameters", "fit_parameter_source", "source_of_fit",
           "preset_parameter_source", "materials_parameter_source"]


def contact_attributes(contacts: Contact | Sequence[Contact]) -> dict:
    """``contact_<field>`` attributes of one contact (floats) or of one contact per size (arrays).

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> a = contact_attributes(c)
    >>> a["contact_radius"], a["contact_normal_model"], a["contact_damping_reference_speed"]
    (3.45e-06, 'ring', 'per-impact normal speed')
    >>> a["contact_shear_modulus"], a["contact_tangential_stiffness"], a["contact_rolling_stiffness"]
    ('not given', 'not given', 'not given')
    >>> contact_attributes([c, c.with_(radius=1e-6)])["contact_radius"].tolist()  # one per size
    [3.45e-06, 1e-06]
    """
    many = not isinstance(contacts, Contact)
    group = list(contacts) if many else [contacts]
    attrs = {}
    for f in fields(Contact):
        values = [getattr(c, f.name) for c in group]
        if f.name in SUB_MODELS:  # a sub-model name, one per file (sizes share it)
            attrs[f"contact_{f.name}"] = ", ".join(sorted(set(values)))
        elif any(v is None for v in values):
            # None: the damping reference speed is each impact's own; any other optional field
            # (G*, the DEM springs) is not given, its law not being selected
            attrs[f"contact_{f.name}"] = ("per-impact normal speed" if f.name == "damping_reference_speed"
                                          else "not given")
        else:
            attrs[f"contact_{f.name}"] = np.array(values, dtype=float) if many else float(values[0])
    return attrs


def stamp_parameters(ds: xr.Dataset, contacts: Contact | Sequence[Contact], source: str) -> xr.Dataset:
    """A copy of ``ds`` with the ``contact_*`` attributes of ``contacts`` and ``parameter_source``.

    Examples
    --------
    The Dataset passed in is not modified:

    >>> import xarray as xr
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> ds = xr.Dataset()
    >>> out = stamp_parameters(ds, c, preset_parameter_source("paper"))
    >>> out.attrs["parameter_source"], out.attrs["contact_density"], len(ds.attrs)
    ('preset: paper', 1350.0, 0)
    """
    out = ds.copy()
    out.attrs.update(contact_attributes(contacts))
    out.attrs["parameter_source"] = source
    return out


def fit_parameter_source(source, sha256) -> str:
    """``"fit: <data file name> <sha256>"``: parameters fitted to the data file ``source``.

    Only the file's name is kept (no directories of the machine that ran the fit); the sha256 of
    its bytes identifies it. ``unknown`` stands for what was not recorded (a table built in memory).

    Examples
    --------
    >>> fit_parameter_source("impacts.csv", "ab" * 32)[:28]
    'fit: impacts.csv abababababa'
    """
    name = Path(str(source)).name if source else "unknown"
    return f"fit: {name} {sha256 or 'unknown'}"


def source_of_fit(fit: xr.Dataset) -> str:
    """The ``parameter_source`` of a fit Dataset (``DampingFit.to_dataset`` or its file).

    Examples
    --------
    >>> import xarray as xr
    >>> source_of_fit(xr.Dataset(attrs={"fit_source": "impacts.csv", "fit_sha256": "ab" * 32}))[:28]
    'fit: impacts.csv abababababa'
    >>> source_of_fit(xr.Dataset(attrs={"parameter_source": "preset: wall1990"}))
    'preset: wall1990'
    """
    return fit.attrs.get("parameter_source") or fit_parameter_source(fit.attrs.get("fit_source"),
                                                                     fit.attrs.get("fit_sha256"))


def preset_parameter_source(name: str) -> str:
    """``"preset: <name>"``: parameters from a named set of :mod:`microimpact.presets`.

    Examples
    --------
    >>> preset_parameter_source("wall1990")
    'preset: wall1990'
    """
    return f"preset: {name}"


def materials_parameter_source(pair: str) -> str:
    """``"materials: <pair>"``: parameters from a pair of a materials config.

    Examples
    --------
    >>> materials_parameter_source("ammonium_fluorescein_on_silicon")
    'materials: ammonium_fluorescein_on_silicon'
    """
    return f"materials: {pair}"
