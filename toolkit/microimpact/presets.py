"""Parameter sets from the literature.

``WALL_1990`` is row 2 of Table 1 of Cheng, Brach & Dunn (2002), doi:10.1080/02786820290092221:
ammonium fluorescein microspheres on polished silicon after Wall et al. (1990),
Aerosol Sci. Technol. 12:926-946, doi:10.1080/02786829008959404.
"""

from __future__ import annotations

from microimpact.model.contact import Contact

__all__ = ["WALL_1990", "PRESETS", "get_preset"]

WALL_1990 = Contact(
    radius=3.45e-6,
    density=1350.0,
    stiffness=1.776e9,
    adhesion_line_force=7.422,
    zeta_hertz=0.50,
    zeta_adhesion=29.0,
    friction=0.15,
)

PRESETS: dict[str, Contact] = {"wall1990": WALL_1990}


def get_preset(name: str) -> Contact:
    """The preset called ``name`` (case-insensitive); ValueError listing the known names otherwise."""
    try:
        return PRESETS[name.lower()]
    except KeyError:
        raise ValueError(f"unknown preset {name!r}; known presets: {', '.join(sorted(PRESETS))}") from None
