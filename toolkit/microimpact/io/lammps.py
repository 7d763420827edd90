"""The contact as LAMMPS GRANULAR input: one ``fix wall/gran`` line for a sphere on a wall.

Which laws map, and how (LAMMPS documentation of ``pair_style granular`` and ``fix wall/gran``,
https://docs.lammps.org/pair_granular.html, https://docs.lammps.org/fix_wall_gran.html):

=====================================  ==========================================================
microimpact                            LAMMPS GRANULAR (wall contact)
=====================================  ==========================================================
``normal_model="ring"``, f0 = 0        ``hertz/material E 0.0 nu``: (4/3) E_eff sqrt(R) delta^(3/2)
``normal_model="jkr_force"``           ``jkr E 0.0 nu gamma``: JKR, contact lost at F = -F_c
``normal_model="dmt"``                 ``dmt E 0.0 nu gamma``: Hertz - 4 pi gamma R
no damping (zeta_H = zeta_A = 0)       ``damping viscoelastic`` with the prefactor 0.0
``damping_model`` (DEM laws)           ``damping`` of the same name, its coefficient in the
                                       normal law's damping slot (model/dem_damping.py);
                                       ``tsuji`` as the identical ``coeff_restitution`` law
no friction (f = 0)                    ``tangential linear_nohistory 0.0 0.0``
``tangential_model="linear_history"``  ``tangential linear_history k_t x_gamma,t f``
``tangential_model="lammps_mindlin"``  ``tangential mindlin 8G* x_gamma,t f`` (and its variants
                                       ``mindlin_rescale``, ``mindlin/force``, ``mindlin_rescale/force``)
                                       (:mod:`microimpact.model.dem_tangential`)
``rolling_model="lammps_sds"``         ``rolling sds k_roll gamma_roll mu_roll``
                                       (:mod:`microimpact.model.dem_rolling`)
``twisting_model="lammps_sds"``        ``twisting sds k_twist gamma_twist mu_twist``
``twisting_model="lammps_marshall"``   ``twisting marshall`` (:mod:`microimpact.model.dem_twisting`;
                                       not written without friction, where it has no effect)
=====================================  ==========================================================

Conversions. LAMMPS mixes the wall's modulus with the particle's as for two particles of the same
material, E_eff = E / (2 (1 - nu^2)) (checked against LAMMPS: a Hertz contact time agrees to 2e-15
with this mixing and is 32 % longer with E_eff = E / (1 - nu^2)); microimpact's stiffness is
K = (4/3) E_eff (Eq. 3 of Cheng et al. 2002), so E = (3/2) (1 - nu^2) K for any nu. LAMMPS's
``gamma`` is a surface energy, half the work of adhesion: its JKR pull-off force 3 pi gamma R is
(3/2) pi w_A R for gamma = w_A / 2, and its DMT force 4 pi gamma R is 2 pi w_A R.

What is refused (:class:`LammpsExportError`, naming the parameter), because LAMMPS has no law that
gives the same impact:

* the paper's ring adhesion force (``normal_model="ring"`` with f0 > 0) and the
  displacement-controlled JKR break (``normal_model="jkr"``; use ``"jkr_force"``);
* the paper's nonlinear damping (zeta_H, zeta_A > 0): LAMMPS's ``velocity``, ``mass_velocity``,
  ``viscoelastic``, ``tsuji`` and ``coeff_restitution`` damping are other laws;
* friction (f > 0) with microimpact's own tangential laws: the paper's rigid contact is no LAMMPS
  law, and microimpact's "mindlin" (micro-slip) and "mindlin_deresiewicz" (hysteresis) agree with
  LAMMPS's ``mindlin`` variants only while the contact slides throughout (above about 60 deg
  incidence for f = 0.3; docs/guide/lammps.md); choose LAMMPS's own laws, ``linear_history`` or
  ``lammps_mindlin``;
* rolling resistance with microimpact's constant torque mu_r r |F_n| (``rolling_model="torque"``): it
  is not LAMMPS's spring-dashpot-slider; ``rolling_model="lammps_sds"`` is, and is written as
  ``rolling sds k_roll gamma_roll mu_roll``.

Units. The numbers are written in one of LAMMPS's unit styles ``si``, ``cgs``, ``micro`` or
``nano`` (:data:`LAMMPS_UNITS`), named in the header; the including script sets that style.

The header records, as comments, the toolkit version, where the parameters came from (a fit's data
file and its sha256), the fitted values, and the whole contact as one JSON line that
:func:`read_lammps_contact` reads back (the verification, :mod:`microimpact.studies.lammps_check`,
runs LAMMPS on the file and compares it with microimpact's prediction for that contact). A file
written by ``microimpact lammps fit`` also carries the fit as one JSON line (:data:`FIT_LINE`,
:data:`FIT_RECORD_KEYS`): the law, its verdict (chi-square, degrees of freedom, p), the misfit in
words, whether it is the closest of laws that were all rejected, and every radius of the data with
its measured speed range and largest e_n error, which ``verify`` checks LAMMPS over. Both JSON
lines are read as data, field by field against a fixed schema; nothing in them is run.

References
----------
LAMMPS documentation, ``pair_style granular`` and ``fix wall/gran`` (version 22 Jul 2025),
https://docs.lammps.org/pair_granular.html.

Cheng, W., Brach, R. M. and Dunn, P. F. (2002), Aerosol Sci. Technol. 36:1081-1093,
doi:10.1080/02786820290092221.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, fields

from microimpact import __version__
from microimpact.model.contact import Contact
from microimpact.model.dem_damping import restitution_of_damping_factor, tsuji_damping_factor
from microimpact.model.dem_rolling import DEM_ROLLING_MODELS
from microimpact.model.dem_twisting import DEM_TWISTING_MODELS
from microimpact.model.dem_tangential import DEM_TANGENTIAL_MODELS
from microimpact.model.tangential_compliance import effective_shear_modulus, shear_modulus_from_elastic

__all__ = ["LAMMPS_UNITS", "DEFAULT_POISSON", "LammpsExportError", "LammpsWallModel", "lammps_wall_model",
           "lammps_input", "lammps_expressible", "read_lammps_contact", "read_lammps_export", "LammpsExport",
           "lammps_fix_line", "lammps_scales", "CONTACT_LINE", "UNITS_LINE", "FIT_LINE", "FIT_RECORD_KEYS",
           "check_fit_record"]

#: LAMMPS unit styles: (metre, kilogram, second) per unit of length, mass and time
#: (https://docs.lammps.org/units.html)
LAMMPS_UNITS: dict[str, tuple[float, float, float]] = {
    "si": (1.0, 1.0, 1.0),
    "cgs": (1e-2, 1e-3, 1.0),
    "micro": (1e-6, 1e-15, 1e-6),
    "nano": (1e-9, 1e-21, 1e-9),
}
#: Poisson ratio written with E when the caller gives none. With the explicit modulus of
#: lammps_wall_model it changes no force (E is chosen to give the contact's K whatever nu is);
#: it matters only if a user edits E by hand.
DEFAULT_POISSON = 0.3
#: prefix of the header line that carries the contact as JSON
CONTACT_LINE = "# microimpact-contact: "
#: prefix of the header line that carries the fit ``lammps fit`` wrote the file from, as JSON
FIT_LINE = "# microimpact-fit: "
#: the fields of the fit line and the type of each (``number``: finite, or null where not
#: applicable); any other field, or a missing one, is refused
FIT_RECORD_KEYS = {"law": "text", "verdict": "text", "chi_square": "number", "degrees_of_freedom": "number",
                   "p_value": "number", "misfit": "text", "closest_of_rejected": "flag", "data": "ranges"}
#: the fields of each entry of the fit line's ``data``: one radius of the data, its measured normal
#: speed range and where the law's e_n misses it most
FIT_RANGE_KEYS = ("radius", "speed_min", "speed_max", "impacts", "largest_error", "speed")
#: verdicts a fit line may state (:mod:`microimpact.analysis.verdict`)
_FIT_VERDICTS = ("adequate", "inadequate", "no stated uncertainties")
#: the longest text field and the most radii a fit line may hold (a record, not a payload)
_FIT_TEXT_MAX, _FIT_RANGES_MAX = 2000, 1000
#: prefix of the header line that names the unit style of the numbers (a comment, not a ``units``
#: command: LAMMPS refuses ``units`` once the box exists, and the fix must come after the box)
UNITS_LINE = "# microimpact-units: "
#: the starts of the comment lines :func:`lammps_input` writes; :func:`read_lammps_export` refuses
#: any other line but the contact, units and fix lines
HEADER_PREFIXES = ("# LAMMPS GRANULAR wall contact written by microimpact ", "# law: ", "# the numbers are in LAMMPS units ",
                   "# sphere: ", "# E = ", "# tangential ", "# rolling sds: ", "# twisting sds: ",
                   "# twisting marshall: ", "# damping tsuji ", "# parameters from: ", "# fitted ",
                   "# check with: microimpact lammps verify ")
#: a control character (a newline, a carriage return, a tab, an escape, NUL, C1, a Unicode line or
#: paragraph separator): in a LAMMPS input a newline starts a new command, so no written string
#: may hold one
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f\u2028\u2029]")
#: a number as the export writes it (``%.15g``) or LAMMPS's NULL of an open wall side
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
#: the wall styles of ``fix wall/gran`` the export writes and verify reads: a plane (its low and high
#: side, a number or NULL) or a z cylinder (its radius), optionally moving (``wiggle``, ``shear``)
#: (https://docs.lammps.org/fix_wall_gran.html)
WALL = re.compile(rf"(?:[xyz]plane (?:{_NUMBER}|NULL) (?:{_NUMBER}|NULL)|zcylinder {_NUMBER})"
                  rf"(?: wiggle [xyz] {_NUMBER} {_NUMBER}| shear [xyz] {_NUMBER})?")
#: a LAMMPS fix ID or group name: letters, digits and underscores (https://docs.lammps.org/fix.html)
_IDENTIFIER = re.compile(r"[A-Za-z0-9_]+")


class LammpsExportError(ValueError):
    """The contact uses a law or a parameter that LAMMPS GRANULAR cannot express; the message names it.

    Examples
    --------
    The paper's contact (ring adhesion, nonlinear damping, rigid Coulomb friction) has no LAMMPS
    form; every refused field is named:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> lammps_wall_model(c)
    Traceback (most recent call last):
    ...
    microimpact.io.lammps.LammpsExportError: cannot be written as LAMMPS GRANULAR input:
    adhesion_line_force=7.422 with normal_model='ring': ...
    """


@dataclass(frozen=True)
class LammpsWallModel:
    """The LAMMPS GRANULAR wall law of a contact, in SI units.

    Attributes
    ----------
    normal : str
        ``"hertz/material"``, ``"jkr"`` or ``"dmt"``.
    youngs_modulus : float
        E written for both the particle and the wall, E_eff = E / (2 (1 - nu^2)). [Pa]
    poisson : float
        nu. [-]
    surface_energy : float
        LAMMPS's gamma = w_A / 2 (0 for hertz/material). [J/m^2]
    damping : float
        The damping coefficient written with the normal law: eta_n0 of ``viscoelastic`` [1/(s m)]
        (0: undamped) or of ``mass_velocity`` [1/s], the restitution e of ``tsuji`` and
        ``coeff_restitution`` [-].
    tangential : str
        LAMMPS's tangential keyword: ``"linear_nohistory"`` (no friction: its coefficients are 0),
        ``"linear_history"``, ``"mindlin"`` or a Mindlin variant (``"mindlin_rescale"``, ``"mindlin/force"``,
        ``"mindlin_rescale/force"``).
    damping_model : str
        LAMMPS's damping keyword (microimpact's ``damping_model``; ``viscoelastic`` when undamped).
    tangential_stiffness : float
        k_t of ``linear_history`` [N/m], 8 G* of ``mindlin`` [Pa]; 0 for ``linear_nohistory``.
    tangential_damping : float
        x_gamma,t. [-]
    friction : float
        mu. [-]
    rolling_stiffness, rolling_damping, rolling_friction : float
        k_roll [N/m], gamma_roll [N s/m] and mu_roll [-] of ``rolling sds``
        (:mod:`microimpact.model.dem_rolling`); ``rolling_stiffness`` 0: no rolling law written.
    twisting : str
        LAMMPS's twisting keyword: ``"none"`` (nothing written), ``"sds"`` or ``"marshall"``
        (:mod:`microimpact.model.dem_twisting`).
    twisting_stiffness, twisting_damping, twisting_friction : float
        k_twist [N m/rad], gamma_twist [N m s/rad] and mu_twist [m] of ``twisting sds``.

    Examples
    --------
    See :func:`lammps_wall_model`, which builds it from a contact. Sphere and wall get the same E
    and nu, so that K = (4/3) E / (2 (1 - nu^2)), i.e. E = 1.5 K (1 - nu^2):

    >>> from microimpact import Contact
    >>> m = lammps_wall_model(Contact(radius=3.45e-6, density=1350.0, stiffness=1e10,
    ...                               adhesion_line_force=0.0))
    >>> m.normal, m.tangential, round(m.youngs_modulus / (1.5 * 1e10 * (1.0 - m.poisson**2)), 12)
    ('hertz/material', 'linear_nohistory', 1.0)
    """

    normal: str
    youngs_modulus: float
    poisson: float
    surface_energy: float
    damping: float
    tangential: str
    damping_model: str = "viscoelastic"
    tangential_stiffness: float = 0.0
    tangential_damping: float = 0.0
    friction: float = 0.0
    rolling_stiffness: float = 0.0
    rolling_damping: float = 0.0
    rolling_friction: float = 0.0
    twisting: str = "none"
    twisting_stiffness: float = 0.0
    twisting_damping: float = 0.0
    twisting_friction: float = 0.0

    def granular_args(self, units: str = "si") -> str:
        """The model arguments after ``granular`` of ``fix wall/gran``, in LAMMPS units ``units``."""
        length, mass, time = _check_units(units)
        pressure = mass / (length * time**2)  # Pa per unit of pressure
        energy_area = mass / time**2  # J/m^2 per unit of energy / area
        damping_unit = {"viscoelastic": 1.0 / (time * length), "mass_velocity": 1.0 / time}.get(self.damping_model, 1.0)
        normal = f"{self.normal} {self.youngs_modulus / pressure:.15g} {self.damping / damping_unit:.15g} {self.poisson:.15g}"
        if self.normal != "hertz/material":
            normal += f" {self.surface_energy / energy_area:.15g}"
        tangential = f"{self.tangential_damping:.15g} {self.friction:.15g}"
        if self.tangential == "linear_nohistory":  # no tangential force
            tangential = "0.0 0.0"
        else:
            stiffness_unit = mass / time**2 if self.tangential == "linear_history" else pressure  # N/m, or Pa
            tangential = f"{self.tangential_stiffness / stiffness_unit:.15g} {tangential}"
        args = f"{normal} damping {self.damping_model} tangential {self.tangential} {tangential}"
        if self.rolling_stiffness > 0.0:  # k_roll in force / distance, gamma_roll in force time / distance
            args += (f" rolling sds {self.rolling_stiffness / (mass / time**2):.15g} "
                     f"{self.rolling_damping / (mass / time):.15g} {self.rolling_friction:.15g}")
        if self.twisting == "sds":  # k_twist a torque (energy), gamma_twist energy time, mu_twist a distance
            energy = mass * length**2 / time**2
            args += (f" twisting sds {self.twisting_stiffness / energy:.15g} "
                     f"{self.twisting_damping / (energy * time):.15g} {self.twisting_friction / length:.15g}")
        elif self.twisting == "marshall":
            args += " twisting marshall"
        return args


def _check_units(units: str) -> tuple[float, float, float]:
    if units not in LAMMPS_UNITS:
        raise LammpsExportError(f"units={units!r}: LAMMPS unit styles written here are {', '.join(LAMMPS_UNITS)}")
    return LAMMPS_UNITS[units]


def _youngs_modulus(stiffness: float, poisson: float) -> float:
    """E of wall and sphere alike that gives the paper's K = (4/3) E* with E* = E / (2 (1 - nu^2)). [Pa]"""
    return 1.5 * (1.0 - poisson**2) * stiffness


def lammps_wall_model(contact: Contact, poisson: float = DEFAULT_POISSON) -> LammpsWallModel:
    """The LAMMPS GRANULAR wall law that gives the impacts of ``contact``, or a refusal.

    Parameters
    ----------
    contact : Contact
    poisson : float
        nu written with E, in (-1, 0.5). [-]

    Returns
    -------
    LammpsWallModel

    Raises
    ------
    LammpsExportError
        If the contact selects a law or a parameter LAMMPS cannot express (module docstring); the
        message names the field and its value.

    References
    ----------
    LAMMPS documentation, ``pair_style granular`` (https://docs.lammps.org/pair_granular.html).

    Examples
    --------
    >>> from microimpact import Contact
    >>> c = Contact(radius=3.45e-6, density=1350.0, stiffness=1e10, adhesion_line_force=7.422,
    ...             normal_model="jkr_force")
    >>> m = lammps_wall_model(c)
    >>> m.normal, round(m.youngs_modulus / 1e10, 6), round(m.surface_energy / c.work_of_adhesion, 12)
    ('jkr', 1.365, 0.5)
    """
    if not -1.0 < poisson < 0.5:
        raise LammpsExportError(f"poisson={poisson!r}: must lie in (-1, 0.5)")
    refused = []
    if contact.normal_model == "ring" and contact.adhesion_line_force > 0.0:
        refused.append(f"adhesion_line_force={contact.adhesion_line_force:g} with normal_model='ring': LAMMPS has no "
                       "adhesion ring force (choose normal_model 'jkr_force' or 'dmt')")
    if contact.normal_model == "jkr":
        refused.append("normal_model='jkr': LAMMPS's jkr breaks contact where the force reaches -F_c, not at the "
                       "critical approach (choose normal_model 'jkr_force')")
    damped = [f"{name}={getattr(contact, name):g}" for name in ("zeta_hertz", "zeta_adhesion") if getattr(contact, name) > 0.0]
    if damped:
        refused.append(f"{', '.join(damped)}: the paper's nonlinear damping is none of LAMMPS's damping laws "
                       "(choose damping_model mass_velocity, viscoelastic, tsuji or coeff_restitution)")
    if contact.friction > 0.0 and contact.tangential_model not in DEM_TANGENTIAL_MODELS:
        refused.append(f"friction={contact.friction:g} with tangential_model={contact.tangential_model!r}: no LAMMPS "
                       "tangential law gives the same impacts (microimpact's Mindlin laws agree with LAMMPS's "
                       "mindlin only while the contact slides throughout)")
    if contact.rolling_friction > 0.0 and contact.rolling_model == "torque":
        refused.append(f"rolling_friction={contact.rolling_friction:g}: microimpact's constant rolling torque is "
                       "not LAMMPS's spring-dashpot-slider (rolling sds)")
    if refused:
        raise LammpsExportError("cannot be written as LAMMPS GRANULAR input: " + "; ".join(refused))
    normal = {"ring": "hertz/material", "jkr_force": "jkr", "dmt": "dmt"}[contact.normal_model]
    youngs = _youngs_modulus(contact.stiffness, poisson)
    gamma = 0.5 * contact.work_of_adhesion if normal != "hertz/material" else 0.0
    damping_model, damping = contact.damping_model, contact.damping_coefficient
    if damping_model == "paper":
        damping_model, damping = "viscoelastic", 0.0
    elif damping_model == "tsuji":  # the same law as coeff_restitution, free of LAMMPS's sqrt(2) change
        damping_model, damping = "coeff_restitution", restitution_of_damping_factor(tsuji_damping_factor(damping))
    tangential, stiffness = "linear_nohistory", 0.0
    if contact.friction > 0.0:
        tangential = DEM_TANGENTIAL_MODELS[contact.tangential_model]
        stiffness = contact.tangential_stiffness if tangential == "linear_history" else 8.0 * contact.shear_modulus
    rolling = (contact.rolling_stiffness, contact.rolling_damping, contact.rolling_friction) \
        if contact.rolling_model in DEM_ROLLING_MODELS else (0.0, 0.0, 0.0)
    twisting = DEM_TWISTING_MODELS.get(contact.twisting_model, "none")
    if twisting == "marshall" and contact.friction == 0.0:  # its limit 2 a mu / 3 is 0: no torque
        twisting = "none"
    twisting_sds = (contact.twisting_stiffness, contact.twisting_damping, contact.twisting_friction) \
        if twisting == "sds" else (0.0, 0.0, 0.0)
    return LammpsWallModel(normal, youngs, float(poisson), gamma, damping, tangential, damping_model, stiffness,
                           contact.tangential_damping if contact.friction > 0.0 else 0.0, contact.friction, *rolling,
                           twisting, *twisting_sds)


def lammps_expressible(contact: Contact, poisson: float = DEFAULT_POISSON) -> Contact:
    """The part of ``contact`` that LAMMPS GRANULAR can express: its elasticity and work of adhesion,
    with the force-controlled JKR break (Hertz when f0 = 0), its DEM damping law if it has one
    (:mod:`microimpact.model.dem_damping`; the paper's damping is dropped), its Coulomb friction
    through LAMMPS's ``tangential mindlin`` law, no rolling resistance.

    A contact to check the export with, when the contact itself (the paper's damped ring law, say)
    cannot be written: the same sphere, stiffness, w_A and mu, in LAMMPS's own laws. The Mindlin
    stiffness 8 G* a takes the contact's ``shear_modulus`` G* where it has one, else G* of wall and
    sphere both of the E and nu the export writes (G = E / (2 (1 + nu)), G* = G / (2 (2 - nu)); what
    LAMMPS computes for ``mindlin NULL``), without tangential damping.

    Parameters
    ----------
    contact : Contact
    poisson : float
        nu of the export (:func:`lammps_wall_model`), which sets G* when the contact has none. [-]

    Returns
    -------
    Contact

    References
    ----------
    LAMMPS documentation, ``pair_style granular`` (https://docs.lammps.org/pair_granular.html),
    tangential ``mindlin``.

    Examples
    --------
    >>> from microimpact.presets import WALL_1990
    >>> c = lammps_expressible(WALL_1990)
    >>> c.normal_model, c.zeta_hertz, c.tangential_model, c.friction == WALL_1990.friction
    ('jkr_force', 0.0, 'lammps_mindlin', True)
    >>> lammps_wall_model(c).normal, lammps_wall_model(c).tangential
    ('jkr', 'mindlin')
    >>> round(c.shear_modulus / (0.75 * c.stiffness), 6)  # G* / E* = (1 - nu) / (2 (2 - nu)) at nu = 0.3
    0.205882
    """
    friction = {"friction": 0.0, "tangential_model": "rigid", "shear_modulus": None, "twisting_model": "none",
                "twisting_stiffness": None, "twisting_damping": 0.0, "twisting_friction": 0.0}
    if contact.friction > 0.0:
        shear = contact.shear_modulus
        if shear is None:
            g = float(shear_modulus_from_elastic(_youngs_modulus(contact.stiffness, poisson), poisson))
            shear = float(effective_shear_modulus(g, poisson, g, poisson))
        friction = {"friction": contact.friction, "tangential_model": "lammps_mindlin", "shear_modulus": shear}
    return contact.with_(normal_model="jkr_force" if contact.adhesion_line_force > 0.0 else "ring",
                         zeta_hertz=0.0, zeta_adhesion=0.0, friction_model="net",
                         rolling_friction=contact.rolling_friction if contact.rolling_model != "torque" else 0.0,
                         tangential_stiffness=None, tangential_damping=0.0, **friction)


def _contact_json(contact: Contact) -> str:
    return json.dumps({f.name: getattr(contact, f.name) for f in fields(Contact)}, sort_keys=True)


def lammps_input(contact: Contact, *, units: str = "si", poisson: float = DEFAULT_POISSON,
                 wall: str = "zplane 0.0 NULL", group: str = "all", fix_id: str = "microimpact_wall",
                 source: str = "", fitted: dict | None = None, fit_record: dict | None = None) -> str:
    """LAMMPS input of the wall contact of ``contact``: a header and one ``fix wall/gran`` line.

    Parameters
    ----------
    contact : Contact
    units : {"si", "cgs", "micro", "nano"}
        LAMMPS unit style of the numbers.
    poisson : float
        nu written with E. [-]
    wall : str
        LAMMPS wall style and its arguments (``zplane 0.0 NULL``: the plane z = 0 below the spheres).
    group, fix_id : str
        Group the fix acts on and its ID.
    source : str
        Where the parameters came from (a fit's data file and sha256), written in the header.
    fitted : dict, optional
        Fitted values with their intervals, ``{name: text}``, written in the header.
    fit_record : dict, optional
        The fit the contact comes from, :data:`FIT_RECORD_KEYS` (:func:`check_fit_record`; NaN
        written as null), written as the JSON line :data:`FIT_LINE`.

    Returns
    -------
    str
        The lines, newline-terminated, to ``include`` in a LAMMPS input after its box (``atom_style
        sphere``), whose ``units`` command must name ``units``.

    Raises
    ------
    LammpsExportError
        As :func:`lammps_wall_model`, or for unknown units.

    References
    ----------
    LAMMPS documentation, ``fix wall/gran`` (https://docs.lammps.org/fix_wall_gran.html).

    Examples
    --------
    >>> from microimpact import Contact
    >>> c = Contact(radius=1e-6, density=2500.0, stiffness=5e10, adhesion_line_force=0.0)
    >>> text = lammps_input(c, units="micro")
    >>> [line for line in text.splitlines() if not line.startswith("#")]
    ['fix microimpact_wall all wall/gran granular hertz/material 68250000 0 0.3 damping viscoelastic tangential linear_nohistory 0.0 0.0 zplane 0.0 NULL']
    """
    model = lammps_wall_model(contact, poisson)
    length, mass, _ = _check_units(units)
    _check_text("source", source)
    for name, text in (fitted or {}).items():
        _check_text(f"fitted {name!r}", f"{name} {text}")
    fix = lammps_fix_line(model, units, wall, group, fix_id)
    lines = [
        f"# LAMMPS GRANULAR wall contact written by microimpact {__version__} (microimpact lammps export)",
        (f"# law: {model.normal}, damping {model.damping_model} {model.damping:g}, tangential {model.tangential}"
         f" (microimpact normal_model={contact.normal_model!r}, tangential_model={contact.tangential_model!r})"),
        (f"# the numbers are in LAMMPS units {units}: the script must say 'units {units}' before its box and "
         "include this file after it"),
        (f"# sphere: radius {contact.radius:.10g} m = {contact.radius / length:.10g} length units, "
         f"density {contact.density:.10g} kg/m^3 = {contact.density * length**3 / mass:.10g} mass/length^3"),
        (f"# E = {model.youngs_modulus:.10g} Pa with nu = {model.poisson:g} (wall and particle), "
         f"gamma = w_A / 2 = {model.surface_energy:.10g} J/m^2"),
    ]
    if model.tangential != "linear_nohistory":
        unit = "N/m" if model.tangential == "linear_history" else "Pa (8 G*)"
        lines.append(f"# tangential {model.tangential}: k_t = {model.tangential_stiffness:.10g} {unit}, "
                     f"x_gamma,t = {model.tangential_damping:g}, mu = {model.friction:g}")
    if model.rolling_stiffness > 0.0:
        lines.append(f"# rolling sds: k_roll = {model.rolling_stiffness:.10g} N/m, gamma_roll = "
                     f"{model.rolling_damping:.10g} N s/m, mu_roll = {model.rolling_friction:g}")
    if model.twisting == "sds":
        lines.append(f"# twisting sds: k_twist = {model.twisting_stiffness:.10g} N m/rad, gamma_twist = "
                     f"{model.twisting_damping:.10g} N m s/rad, mu_twist = {model.twisting_friction:.10g} m")
    elif model.twisting == "marshall":
        lines.append("# twisting marshall: k_twist = k_t a^2 / 2, gamma_twist = eta_t a^2 / 2, mu_twist = 2 a mu / 3 "
                     "(from the tangential law)")
    if contact.damping_model == "tsuji":
        lines.append(f"# damping tsuji e = {contact.damping_coefficient:g} (with the sqrt(2) of LAMMPS's development source) "
                     f"is written as the identical law coeff_restitution e = {model.damping:.10g}")
    if source:
        lines.append(f"# parameters from: {source}")
    for name, text in (fitted or {}).items():
        lines.append(f"# fitted {name}: {text}")
    lines.append("# check with: microimpact lammps verify THIS_FILE")
    if fit_record is not None:
        record = _json_ready(fit_record)
        try:
            check_fit_record(record)
        except ValueError as exc:
            raise LammpsExportError(f"fit_record: {exc}") from None
        lines.append(FIT_LINE + json.dumps(record, sort_keys=True, allow_nan=False))  # ASCII: no control character
    lines += [
        CONTACT_LINE + _contact_json(contact),
        UNITS_LINE + units,
        fix,
    ]
    return "\n".join(lines) + "\n"


def _json_ready(obj):
    """Non-finite numbers as null (JSON has none), numpy scalars as Python numbers, tuples as lists."""
    if isinstance(obj, dict):
        return {k: _json_ready(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_json_ready(v) for v in obj]
    if isinstance(obj, (bool, str)) or obj is None:
        return obj
    if isinstance(obj, int) or (hasattr(obj, "dtype") and obj.dtype.kind in "iu"):
        return int(obj)
    value = float(obj)
    return value if math.isfinite(value) else None


def _check_number(where: str, value, *, positive: bool = False, null: bool = True) -> None:
    if value is None and null and not positive:
        return
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{where} must be a finite number{' or null' if null and not positive else ''}, not {value!r}")
    if positive and not value > 0:
        raise ValueError(f"{where} must be > 0, not {value!r}")


def check_fit_record(record) -> dict:
    """The fit line's record, checked field by field (:data:`FIT_RECORD_KEYS`); ValueError naming
    the field otherwise.

    Examples
    --------
    >>> r = {"law": "hertz+coeff_restitution", "verdict": "adequate", "chi_square": 2.1, "degrees_of_freedom": 2,
    ...      "p_value": 0.35, "misfit": "", "closest_of_rejected": False,
    ...      "data": [{"radius": 3e-6, "speed_min": 0.5, "speed_max": 2.0, "impacts": 3, "largest_error": 0.01,
    ...                "speed": 1.0}]}
    >>> check_fit_record(r) is r
    True
    >>> check_fit_record(r | {"run": "shell rm"})
    Traceback (most recent call last):
    ...
    ValueError: field 'run' is not one the fit line holds (law, verdict, chi_square, degrees_of_freedom, p_value, misfit, closest_of_rejected, data)
    """
    if not isinstance(record, dict):
        raise ValueError(f"a JSON object of the fit's fields, not {type(record).__name__}")
    for key in record:
        if key not in FIT_RECORD_KEYS:
            raise ValueError(f"field {key!r} is not one the fit line holds ({', '.join(FIT_RECORD_KEYS)})")
    for key, kind in FIT_RECORD_KEYS.items():
        if key not in record:
            raise ValueError(f"field {key!r} is missing")
        value = record[key]
        if kind == "text" and not (isinstance(value, str) and len(value) <= _FIT_TEXT_MAX):
            raise ValueError(f"field {key!r} must be a text of at most {_FIT_TEXT_MAX} characters")
        if kind == "number":
            _check_number(f"field {key!r}", value)
        if kind == "flag" and not isinstance(value, bool):
            raise ValueError(f"field {key!r} must be true or false, not {value!r}")
    if record["verdict"] not in _FIT_VERDICTS:
        raise ValueError(f"field 'verdict' is {record['verdict']!r}, not one of {', '.join(_FIT_VERDICTS)}")
    ranges = record["data"]
    if not isinstance(ranges, list) or not 1 <= len(ranges) <= _FIT_RANGES_MAX:
        raise ValueError(f"field 'data' must be a list of 1 to {_FIT_RANGES_MAX} radii")
    for i, entry in enumerate(ranges, 1):
        if not isinstance(entry, dict) or sorted(entry) != sorted(FIT_RANGE_KEYS):
            raise ValueError(f"field 'data', entry {i}: must have exactly the fields {', '.join(FIT_RANGE_KEYS)}")
        for key in ("radius", "speed_min", "speed_max"):
            _check_number(f"field 'data', entry {i}, {key!r}", entry[key], positive=True)
        for key in ("largest_error", "speed"):
            _check_number(f"field 'data', entry {i}, {key!r}", entry[key])
        if entry["speed_max"] < entry["speed_min"]:
            raise ValueError(f"field 'data', entry {i}: speed_max {entry['speed_max']!r} < speed_min {entry['speed_min']!r}")
        if isinstance(entry["impacts"], bool) or not isinstance(entry["impacts"], int) or entry["impacts"] < 1:
            raise ValueError(f"field 'data', entry {i}, 'impacts' must be a whole number >= 1, not {entry['impacts']!r}")
    return record


def _check_text(name: str, value: str) -> None:
    """LammpsExportError naming ``name`` if ``value`` holds a control character (a newline would
    start a second LAMMPS command in the file)."""
    found = _CONTROL.search(value)
    if found:
        raise LammpsExportError(f"{name}: holds the control character U+{ord(found.group()):04X} at position "
                                f"{found.start() + 1} (a newline would start a LAMMPS command of its own)")


def lammps_fix_line(model: LammpsWallModel, units: str, wall: str = "zplane 0.0 NULL", group: str = "all",
                    fix_id: str = "microimpact_wall") -> str:
    """The one ``fix wall/gran`` command of the wall law ``model``, in LAMMPS units ``units``.

    Parameters
    ----------
    model : LammpsWallModel
    units : {"si", "cgs", "micro", "nano"}
    wall : str
        Wall style and arguments (:data:`WALL`: ``xplane|yplane|zplane LO HI`` or ``zcylinder R``, a
        side a number or NULL, optionally ``wiggle`` or ``shear``).
    group, fix_id : str
        Letters, digits and underscores.

    Raises
    ------
    LammpsExportError
        For a wall, group or ID outside that grammar (a control character, a second command).

    Examples
    --------
    >>> from microimpact import Contact
    >>> m = lammps_wall_model(Contact(radius=1e-6, density=2500.0, stiffness=5e10, adhesion_line_force=0.0))
    >>> lammps_fix_line(m, "si", wall="zplane 0.0 NULL\\nshell touch X")
    Traceback (most recent call last):
    ...
    microimpact.io.lammps.LammpsExportError: wall: holds the control character U+000A at position 16 (a newline would start a LAMMPS command of its own)
    """
    _check_text("wall", wall)
    if not WALL.fullmatch(wall):
        raise LammpsExportError(f"wall={wall!r}: not a wall of fix wall/gran written here (xplane, yplane or zplane "
                                "LO HI, or zcylinder RADIUS, each a number or NULL; optionally wiggle or shear)")
    for name, value in (("group", group), ("fix_id", fix_id)):
        if not _IDENTIFIER.fullmatch(value):
            raise LammpsExportError(f"{name}={value!r}: a LAMMPS name has letters, digits and underscores only")
    return f"fix {fix_id} {group} wall/gran granular {model.granular_args(units)} {wall}"


@dataclass(frozen=True)
class LammpsExport:
    """What a file written by :func:`lammps_input` holds, read back and checked line by line.

    Attributes
    ----------
    contact : Contact
        The contact of the header's JSON line.
    units : str
        The LAMMPS unit style of the numbers.
    poisson : float
        nu written with E. [-]
    wall, group, fix_id : str
        The wall of the fix line, its group and ID.
    fix_line_number : int
        Line of the file holding the ``fix wall/gran`` command (1-based).
    fit : dict or None
        The fit line's record (:func:`check_fit_record`) of a file written by ``lammps fit``; None
        for ``lammps export``.
    """

    contact: Contact
    units: str
    poisson: float
    wall: str
    group: str
    fix_id: str
    fix_line_number: int
    fit: dict | None = None

    @property
    def data_ranges(self) -> tuple:
        """((radius [m], lowest, highest measured normal speed [m/s]), ...) of the fitted data, one
        per radius; empty without a fit line."""
        if not self.fit:
            return ()
        return tuple((e["radius"], e["speed_min"], e["speed_max"]) for e in self.fit["data"])

    def script(self) -> str:
        """The one LAMMPS command of this contact, rebuilt from the parsed parameters (never the
        file's own text): what ``microimpact lammps verify`` runs."""
        return lammps_fix_line(lammps_wall_model(self.contact, self.poisson), self.units, self.wall, self.group,
                               self.fix_id) + "\n"


def _file_lines(text: str) -> list[str]:
    """The lines of ``text`` split at newlines only (``str.splitlines`` also splits at a form feed
    or a line separator, which LAMMPS does not), a final newline ending the last."""
    lines = text.split("\n")
    return lines[:-1] if lines and lines[-1] == "" else lines


def read_lammps_export(text: str) -> LammpsExport:
    """Parse a file written by :func:`lammps_input`; refuse any line that it does not write.

    Accepted: the header comments (:data:`HEADER_PREFIXES`), one contact line (JSON of a
    :class:`Contact`), at most one fit line (:data:`FIT_LINE`, checked by :func:`check_fit_record`),
    one units line, and last one ``fix wall/gran`` command whose every parameter
    is what the export of that contact writes (the Poisson ratio, wall, group and ID as written).
    Everything else (``shell``, ``run``, ``include``, ``python``, a second command, a blank line, a
    control character such as an injected newline) is refused, naming its line: a file received from
    someone else is data, and nothing in it is run.

    Raises
    ------
    ValueError
        Naming the line (1-based) and what is wrong with it.

    References
    ----------
    LAMMPS documentation, ``fix wall/gran`` (https://docs.lammps.org/fix_wall_gran.html).

    Examples
    --------
    >>> from microimpact import Contact
    >>> c = Contact(radius=1e-6, density=2500.0, stiffness=5e10, adhesion_line_force=0.0)
    >>> text = lammps_input(c, units="nano")
    >>> export = read_lammps_export(text)
    >>> export.contact == c, export.units, export.script() == text.splitlines()[-1] + "\\n"
    (True, 'nano', True)
    >>> read_lammps_export(text + "shell touch X\\n")
    Traceback (most recent call last):
    ...
    ValueError: line 10: 'shell touch X' after the fix line (line 9): the export writes nothing after its fix line
    """
    record = units = fix = fit = None
    for number, line in enumerate(_file_lines(text), 1):
        found = _CONTROL.search(line)
        if found:
            raise ValueError(f"line {number}: the control character U+{ord(found.group()):04X} at column "
                             f"{found.start() + 1} (an injected line?): not written by 'microimpact lammps export'")
        if fix is not None:
            raise ValueError(f"line {number}: {line[:60]!r} after the fix line (line {fix}): the export writes nothing "
                             "after its fix line")
        if line.startswith(CONTACT_LINE):
            if record is not None:
                raise ValueError(f"line {number}: a second contact line (the first is line {record[0]})")
            record = (number, _contact_of_line(number, line[len(CONTACT_LINE):]))
        elif line.startswith(FIT_LINE):
            if fit is not None:
                raise ValueError(f"line {number}: a second fit line (the first is line {fit[0]})")
            fit = (number, _fit_of_line(number, line[len(FIT_LINE):]))
        elif line.startswith(UNITS_LINE):
            if units is not None:
                raise ValueError(f"line {number}: a second units line (the first is line {units[0]})")
            units = (number, line[len(UNITS_LINE):].strip())
            if units[1] not in LAMMPS_UNITS:
                raise ValueError(f"line {number}: units {units[1]!r} is not one of {', '.join(LAMMPS_UNITS)}")
        elif line.startswith("fix "):
            missing = [prefix.strip() for prefix, seen in ((CONTACT_LINE, record), (UNITS_LINE, units)) if seen is None]
            if missing:
                raise ValueError(f"line {number}: the fix line comes before any '{missing[0]}' line: not written by "
                                 "'microimpact lammps export'")
            fix = number
            fields_ = _fix_line_fields(number, line, record, units[1])
        elif not line.startswith(HEADER_PREFIXES):
            raise ValueError(f"line {number}: {line[:60]!r} is not a line 'microimpact lammps export' writes (only "
                             "its header comments, the contact and units lines and one fix wall/gran command)")
    if record is None:
        raise ValueError(f"no '{CONTACT_LINE.strip()}' line: not written by 'microimpact lammps export'")
    if units is None:
        raise ValueError(f"no '{UNITS_LINE.strip()}' line: not written by 'microimpact lammps export'")
    if fix is None:
        raise ValueError("no fix wall/gran line after the contact and units lines: not written by "
                         "'microimpact lammps export'")
    return LammpsExport(record[1], units[1], fix_line_number=fix, fit=None if fit is None else fit[1], **fields_)


def _fit_of_line(number: int, text: str) -> dict:
    def constant(name):  # NaN and Infinity are not JSON; the export writes null
        raise ValueError(f"{name} is not a JSON number")

    try:
        return check_fit_record(json.loads(text, parse_constant=constant))
    except ValueError as exc:
        raise ValueError(f"line {number}: the fit record does not read: {exc}") from None


def _contact_of_line(number: int, text: str) -> Contact:
    try:
        record = json.loads(text)
        if not isinstance(record, dict):
            raise TypeError(f"a JSON object of the contact's fields, not {type(record).__name__}")
        return Contact(**record)
    except (ValueError, TypeError) as exc:
        raise ValueError(f"line {number}: the contact record does not read: {exc}") from None


def _fix_line_fields(number: int, line: str, record: tuple, units: str) -> dict:
    """poisson, wall, group and fix_id of the fix line ``line``, which must be the export of the
    contact ``record`` (line, Contact) in ``units``, word for word; ValueError naming what differs."""
    words = line.split(" ")
    if len(words) < 10 or words[3:5] != ["wall/gran", "granular"]:
        raise ValueError(f"line {number}: {line[:60]!r} is not the export's 'fix ID GROUP wall/gran granular ...' line")
    try:
        poisson = float(words[8])
    except ValueError:
        poisson = math.nan
    if not re.fullmatch(_NUMBER, words[8]) or not math.isfinite(poisson):
        raise ValueError(f"line {number}: word 9 {words[8][:30]!r} of the fix line is not the Poisson ratio of its "
                         "normal law")
    contact_line, contact = record
    try:
        model = lammps_wall_model(contact, poisson)
        args = f"{words[0]} {words[1]} {words[2]} wall/gran granular {model.granular_args(units)}"
        wall = line[len(args) + 1:] if line.startswith(args + " ") else None
        expected = lammps_fix_line(model, units, wall, words[2], words[1]) if wall is not None else args
    except LammpsExportError as exc:
        raise ValueError(f"line {number}: {exc}") from None
    if expected != line:
        mine, theirs = expected.split(" "), words
        at = next((i for i, (a, b) in enumerate(zip(mine, theirs)) if a != b), min(len(mine), len(theirs)))
        found = theirs[at] if at < len(theirs) else "(the end of the line)"
        want = mine[at] if at < len(mine) else "(the end of the line)"
        raise ValueError(f"line {number}: word {at + 1} of the fix line is {found[:30]!r} where the export of the "
                         f"contact on line {contact_line} writes {want!r}: the parameters are not the contact's")
    return {"poisson": poisson, "wall": wall, "group": words[2], "fix_id": words[1]}


def read_lammps_contact(text: str) -> tuple[Contact, str]:
    """The contact and the unit style recorded in a file written by :func:`lammps_input`
    (:func:`read_lammps_export`, which checks every line).

    Raises
    ------
    ValueError
        If a line is not one the export writes, or the contact, units or fix line is missing,
        naming the line or what is missing.

    Examples
    --------
    >>> from microimpact import Contact
    >>> c = Contact(radius=1e-6, density=2500.0, stiffness=5e10, adhesion_line_force=0.0)
    >>> read_lammps_contact(lammps_input(c, units="nano")) == (c, "nano")
    True
    """
    export = read_lammps_export(text)
    return export.contact, export.units


def lammps_scales(units: str) -> dict[str, float]:
    """SI value of one LAMMPS unit of length, mass, time, speed, density and angular speed.

    Examples
    --------
    LAMMPS's ``micro`` style: micrometres, picograms, microseconds:

    >>> s = lammps_scales("micro")
    >>> s["length"], s["mass"], s["time"]
    (1e-06, 1e-15, 1e-06)
    """
    length, mass, time = _check_units(units)
    return {"length": length, "mass": mass, "time": time, "speed": length / time,
            "density": mass / length**3, "angular_speed": 1.0 / time}

