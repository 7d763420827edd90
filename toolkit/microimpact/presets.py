"""Named contacts from the literature (public API; the numbers live in :mod:`microimpact.model.parameters`).

``WALL_1990`` is row 2 of Table 1 of Cheng, Brach & Dunn (2002), doi:10.1080/02786820290092221:
ammonium fluorescein microspheres on polished silicon after Wall et al. (1990),
Aerosol Sci. Technol. 12:926-946, doi:10.1080/02786829008959404.
"""

from __future__ import annotations

from collections.abc import Mapping

from microimpact.io.provenance import preset_parameter_source
from microimpact.model.contact import Contact
from microimpact.model.parameters import TABLE1, TABLE1_ROW2

__all__ = ["WALL_1990", "PRESETS", "get_preset", "named_contact"]

WALL_1990 = TABLE1_ROW2

PRESETS: dict[str, Contact] = {
    "wall1990": WALL_1990,
    **{f"table1_{name}": contact for name, contact in TABLE1.items()},
}


def get_preset(name: str) -> Contact:
    """The preset called ``name`` (case-insensitive); ValueError listing the known names otherwise.

    Examples
    --------
    >>> c = get_preset("WALL1990")
    >>> c.radius, c.adhesion_line_force, c.zeta_hertz, c.zeta_adhesion
    (3.45e-06, 7.422, 0.5, 29.0)
    """
    try:
        return PRESETS[name.lower()]
    except KeyError:
        raise ValueError(f"unknown preset {name!r}; known presets: {', '.join(sorted(PRESETS))}") from None


def named_contact(spec: str | Mapping) -> tuple[Contact, str]:
    """The contact that a config names, and its ``parameter_source``.

    Parameters
    ----------
    spec : str or mapping
        A preset name (:data:`microimpact.presets.PRESETS`, e.g. ``"wall1990"`` = Table 1 row 2)
        or a mapping of :class:`Contact` fields in SI units.

    Returns
    -------
    (Contact, str)
        The contact and ``"preset: <name>"`` or ``"config"``.

    Examples
    --------
    >>> named_contact("wall1990")[1]
    'preset: wall1990'
    >>> c, source = named_contact({"radius": 2e-6, "density": 1350.0, "stiffness": 1.776e9, "adhesion_line_force": 7.0})
    >>> source, c.radius
    ('config', 2e-06)
    """
    if isinstance(spec, str):
        return get_preset(spec), preset_parameter_source(spec.lower())
    return Contact(**spec), "config"
