"""The paper's parameter sets, each defined once and referenced by name everywhere else.

Table 1 of Cheng, Brach & Dunn (2002), doi:10.1080/02786820290092221: ammonium fluorescein
microspheres on polished silicon after Wall et al. (1990), Aerosol Sci. Technol. 12:926-946,
doi:10.1080/02786829008959404. Table 2: the initial conditions of the oblique-impact studies
(Figs. 7-14). Presets (:mod:`microimpact.presets`), the CLI, the pipeline's config and the tests
name these sets; none of them repeats a number.

Table 1 row 1 spans r = 1.29-3.45 um with f0 = 5.340-7.390 N/m; its two ends are given as two
contacts. Rows 2 and 3 are the same contact; row 3 sweeps the friction over 0.10-0.90 (Table 2
cases 2.4 and 2.5 do so).
"""

from __future__ import annotations

from types import MappingProxyType

from microimpact.model.contact import Contact

__all__ = ["TABLE1", "TABLE1_ROW2", "TABLE2_CASES", "table2_case"]

_WALL = dict(density=1350.0, stiffness=1.776e9, zeta_hertz=0.50, zeta_adhesion=29.0, friction=0.15)

#: Table 1 row 2 (Figs. 5, 7-12; row 3, Figs. 13-14, differs only in the friction swept)
TABLE1_ROW2 = Contact(radius=3.45e-6, adhesion_line_force=7.422, **_WALL)

#: The rows of Table 1 by name. SI units.
TABLE1: MappingProxyType = MappingProxyType({
    "row1_small": Contact(radius=1.29e-6, adhesion_line_force=5.340, **_WALL),
    "row1_large": Contact(radius=3.45e-6, adhesion_line_force=7.390, **_WALL),
    "row2": TABLE1_ROW2,
})

_SPEED = {"start": 0.2, "stop": 10.0, "num": 50}  # the paper's 0.2-10 m/s in 0.2 m/s steps

#: Grids of the five cases of Table 2, as sweep specs (format: :mod:`microimpact.studies.sweeps`).
#: Where the paper gives no increment the choice is stated in the description. At alpha = 0 the
#: azimuth theta of cases 2.4 and 2.5 has no effect.
TABLE2_CASES: MappingProxyType = MappingProxyType({
    "2.1": {
        "description": "Table 2 case 2.1 (Figs. 7, 8): v = 0.2-10 m/s, alpha = 0-30 deg in 5 deg steps, no spin",
        "speed": dict(_SPEED),
        "incidence_deg": {"start": 0.0, "stop": 30.0, "step": 5.0},
    },
    "2.2": {
        "description": "Table 2 case 2.2 (Figs. 9, 10): v = 0.2-10 m/s, alpha = 0, "
        "omega_t' = 0-1.8e5 rad/s (increment not given in the paper; 6e4 rad/s used)",
        "speed": dict(_SPEED),
        "incidence_deg": 0.0,
        "omega_tp": {"start": 0.0, "stop": 1.8e5, "step": 6.0e4},
    },
    "2.3": {
        "description": "Table 2 case 2.3 (Figs. 11, 12): v = 0.2-10 m/s, alpha = 0-30 deg in 5 deg steps, "
        "omega_t = 2.9e5 rad/s",
        "speed": dict(_SPEED),
        "incidence_deg": {"start": 0.0, "stop": 30.0, "step": 5.0},
        "omega_t": 2.9e5,
    },
    "2.4": {
        "description": "Table 2 case 2.4 (Fig. 13): v = 0.2-10 m/s, alpha = theta = 0, "
        "omega_t = omega_t' = 2.9e5 rad/s, f = 0-0.9 (increment not given; 0.1 used as in Fig. 14)",
        "speed": dict(_SPEED),
        "incidence_deg": 0.0,
        "azimuth_deg": 0.0,
        "omega_t": 2.9e5,
        "omega_tp": 2.9e5,
        "friction": {"start": 0.0, "stop": 0.9, "step": 0.1},
    },
    "2.5": {
        "description": "Table 2 case 2.5 (Fig. 14): v = 0.2-10 m/s, alpha = theta = 0, "
        "omega_t = omega_t' = 2.9e6 rad/s, f = 0-0.9 in 0.1 steps",
        "speed": dict(_SPEED),
        "incidence_deg": 0.0,
        "azimuth_deg": 0.0,
        "omega_t": 2.9e6,
        "omega_tp": 2.9e6,
        "friction": {"start": 0.0, "stop": 0.9, "step": 0.1},
    },
})


def table2_case(name: str) -> dict:
    """A fresh copy of the sweep spec of Table 2 case ``name`` ("2.1" ... "2.5").

    Raises
    ------
    ValueError
        If there is no such case; the message lists the known ones.

    References
    ----------
    Cheng, Brach & Dunn (2002), Table 2

    Examples
    --------
    >>> table2_case("2.1")["speed"]
    {'start': 0.2, 'stop': 10.0, 'num': 50}
    """
    try:
        spec = TABLE2_CASES[str(name)]
    except KeyError:
        raise ValueError(f"unknown Table 2 case {name!r}; known cases: {', '.join(TABLE2_CASES)}") from None
    return {k: dict(v) if isinstance(v, dict) else v for k, v in spec.items()}
