"""Contact parameters of a microsphere on a flat surface and the constants derived from them.

Implements Eqs. (3)-(7), (14)-(15) and (29)-(32) of Cheng, Brach & Dunn (2002),
"Three-Dimensional Modeling of Microsphere Contact/Impact with Smooth, Flat Surfaces",
Aerosol Science and Technology 36(11):1081-1093, doi:10.1080/02786820290092221.

All quantities are SI. Departures from the printed paper:

* Eq. (30) is printed as T = m / (sqrt(r) K X^(1/2)), which has units of s^2. The time scale that
  makes Eq. (28) dimensionless, and C1, C2 of Eqs. (31)-(32) dimensionless, is its square root:
  T = sqrt(m / (sqrt(r) K X^(1/2))) = sqrt(m / sqrt(2 pi r f0 K)).
* Eqs. (14)-(15): the bracket (r^3 K sqrt(v_n) / m)^(2/5) has units of a speed, so C_H and C_A are
  in s/m. The reference speed v_n is, by default, each impact's own incident normal speed (the
  paper's "typically the initial normal velocity"); a fixed reference speed can be set instead.
"""

from __future__ import annotations

import math
import numbers
import sys
from dataclasses import dataclass, fields, replace
from functools import cached_property

import numpy as np

from microimpact.model.dem_rolling import DEM_ROLLING_MODELS
from microimpact.model.dem_twisting import DEM_TWISTING_MODELS
from microimpact.model.dem_tangential import DEM_TANGENTIAL_MODELS

__all__ = ["Contact", "PAPER_REFERENCE", "SUB_MODELS", "check_positive", "check_representable"]

#: the selectable sub-models of the one contact law: field -> accepted names, the first (the
#: paper's model) being the default. "ring" is the paper's adhesion ring force (Eqs. 4-6); "jkr"
#: and "dmt" are the alternative normal adhesion models, "jkr_force" JKR whose contact breaks where
#: the force reaches -F_c (as LAMMPS GRANULAR's jkr) instead of at the critical approach; "rigid" is the paper's tangentially rigid
#: contact (closed-form tangential map), "mindlin" an elastic tangential contact with micro-slip,
#: "mindlin_deresiewicz" the same with the loading/unloading/reloading memory (hysteresis),
#: "linear_history" and the "lammps_mindlin*" variants LAMMPS GRANULAR's history laws (model.dem_tangential);
#: "net" is the paper's Coulomb limit f |F_n|, "pulloff" an adhesion-aware limit that does not vanish
#: at the adhesive equilibrium; "torque" is the constant rolling torque mu_r r |F_n| (with
#: rolling_friction > 0), "lammps_sds" LAMMPS GRANULAR's rolling spring-dashpot-slider (model.dem_rolling);
#: "none" leaves the spin about the normal to the tangential law (the paper's twist torque, or none with
#: LAMMPS's laws), "lammps_sds" and "lammps_marshall" are LAMMPS GRANULAR's twisting laws (model.dem_twisting).
SUB_MODELS: dict[str, tuple[str, ...]] = {
    "normal_model": ("ring", "jkr", "dmt", "jkr_force"),
    "tangential_model": ("rigid", "mindlin", "mindlin_deresiewicz", *DEM_TANGENTIAL_MODELS),
    "friction_model": ("net", "pulloff"),
    "damping_model": ("paper", "mass_velocity", "viscoelastic", "tsuji", "coeff_restitution"),
    "rolling_model": ("torque", *DEM_ROLLING_MODELS),
    "twisting_model": ("none", *DEM_TWISTING_MODELS),
}

#: full citation of the paper, for the ``references`` attribute of the toolkit's results
PAPER_REFERENCE = (
    "Cheng, W., Brach, R. M. and Dunn, P. F. (2002), Three-Dimensional Modeling of Microsphere "
    "Contact/Impact with Smooth, Flat Surfaces, Aerosol Science and Technology 36(11):1081-1093, "
    "doi:10.1080/02786820290092221"
)


def check_positive(name: str, value) -> float:
    """``float(value)`` if it is a finite number > 0; else a ValueError that names ``name`` and the value.

    The one check of a positive input (radius, stiffness, a normal speed [m/s], ...).

    Examples
    --------
    >>> check_positive("radius [m]", "3.45e-6")
    3.45e-06
    >>> check_positive("radius [m]", -1)
    Traceback (most recent call last):
    ...
    ValueError: radius [m] must be a finite number > 0, got -1
    """
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}") from None
    if not math.isfinite(v) or v <= 0.0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return v


#: smallest positive normal double: a derived scale below it has lost its precision (or is 0)
_TINY = sys.float_info.min


def check_representable(what: str, value, culprits: str) -> None:
    """ValueError unless ``value`` (a derived scale, finite and > 0 in exact arithmetic) is a
    finite normal double; the message names the quantity and the inputs it comes from.

    An input can be valid on its own (``stiffness=1e300``) yet give a scale that underflows to 0 or
    overflows to inf, which the solvers would divide by (a ZeroDivisionError) or carry as NaN.

    Examples
    --------
    >>> check_representable("length scale [m]", 0.0, "stiffness=1e300, radius=1e-300")
    Traceback (most recent call last):
    ...
    ValueError: stiffness=1e300, radius=1e-300: the derived length scale [m] is 0.0, outside the floating-point range ...
    """
    v = float(value)
    if not (math.isfinite(v) and v >= _TINY):
        raise ValueError(f"{culprits}: the derived {what} is {v!r}, outside the floating-point range "
                         f"[{_TINY:.3g}, {sys.float_info.max:.3g}]; these values are too extreme together")


def _as_number(name: str, value) -> float:
    """``float(value)`` for a real number (or a text that reads as one, as YAML 1.1 gives for
    ``1e-6``); TypeError naming ``name`` for anything else (bool, complex, None, a dict, an array)."""
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, str)):
        if getattr(value, "ndim", None) == 0 and getattr(value, "dtype", None) is not None and value.dtype.kind in "iuf":
            return float(value)  # a 0-d numpy array
        raise TypeError(f"{name} must be a real number, got {type(value).__name__} {value!r}")
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            raise TypeError(f"{name} must be a real number, got the text {value!r}") from None
    return float(value)


def _check_non_negative(name: str, value: float) -> None:
    if not math.isfinite(value) or value < 0.0:
        raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")


def _check_poisson(name: str, value: float) -> None:
    if not math.isfinite(value) or not -1.0 < value < 0.5:
        raise ValueError(f"{name} must lie in (-1, 0.5), got {value!r}")


#: fields that may be None (not given)
_OPTIONAL = ("damping_reference_speed", "shear_modulus", "tangential_stiffness", "rolling_stiffness",
             "twisting_stiffness")


def _sub_model(name: str, value) -> str:
    """The sub-model name ``value`` of field ``name``, lower-cased; ValueError/TypeError naming it."""
    if not isinstance(value, str):
        raise TypeError(f"{name} must be one of {', '.join(SUB_MODELS[name])}, got {type(value).__name__} {value!r}")
    v = value.strip().lower()
    if v not in SUB_MODELS[name]:
        raise ValueError(f"{name} must be one of {', '.join(SUB_MODELS[name])}, got {value!r}")
    return v


@dataclass(frozen=True)
class Contact:
    """Parameters of a homogeneous elastic microsphere in contact with a flat surface.

    Parameters
    ----------
    radius : float
        Sphere radius r. [m]
    density : float
        Sphere density. [kg/m^3]
    stiffness : float
        Effective material stiffness K = 4 / (3 pi (k1 + k2)), Eq. (3); equals (4/3) E*. [Pa]
    adhesion_line_force : float
        Intensity f0 of the adhesion ring force, Eq. (5). [N/m]
    zeta_hertz : float
        Nondimensional Hertzian damping coefficient zeta_H, Eq. (15). [-]
    zeta_adhesion : float
        Nondimensional adhesion damping coefficient zeta_A, Eq. (14). [-]
    friction : float
        Coulomb friction coefficient f. [-]
    damping_reference_speed : float or None
        Reference speed v_n of Eqs. (14)-(15). None (the paper's default) uses each impact's own
        incident normal speed; a float fixes it for every impact. [m/s]
    normal_model : {"ring", "jkr", "dmt", "jkr_force"}
        Normal adhesion model (:data:`SUB_MODELS`); "ring" is the paper's; "jkr_force" is JKR with the
        force-controlled break of DEM engines (:mod:`microimpact.model.adhesion_models`). [-]
    tangential_model : {"rigid", "mindlin", "mindlin_deresiewicz", "linear_history", "lammps_mindlin", ...}
        Tangential contact model; "rigid" is the paper's; "mindlin_deresiewicz" adds the hysteresis
        of micro-slip (:mod:`microimpact.model.tangential_compliance`); "linear_history" and
        "lammps_mindlin" (with its variants "lammps_mindlin_rescale", "lammps_mindlin_force",
        "lammps_mindlin_rescale_force") are LAMMPS GRANULAR's history laws (:mod:`microimpact.model.dem_tangential`),
        with LAMMPS's normal laws only (ring without adhesion, "jkr_force", "dmt"; no paper damping). [-]
    friction_model : {"net", "pulloff"}
        Coulomb friction limit; "net" (f |F_n|) is the paper's. [-]
    rolling_friction : float
        Rolling-resistance coefficient mu_r of the torque mu_r r |F_n| against the rolling (Zhou et
        al. 1999); 0 (the paper's, no rolling resistance) by default. Needs a compliant tangential
        model (:mod:`microimpact.model.tangential_compliance`). With ``rolling_model="lammps_sds"``
        it is LAMMPS's mu_roll, the limit mu_roll F_n0 of the rolling pseudo-force. [-]
    shear_modulus : float or None
        Effective shear modulus G* of the pair, 1/G* = (2 - nu1)/G1 + (2 - nu2)/G2, needed by the
        "mindlin" tangential model (tangential stiffness 8 G* a); None when not given. [Pa]
    damping_model : {"paper", "mass_velocity", "viscoelastic", "tsuji", "coeff_restitution"}
        Normal damping law; "paper" (zeta_H, zeta_A) is the paper's; the others are the damping
        laws of LAMMPS GRANULAR (:mod:`microimpact.model.dem_damping`), with zeta_H = zeta_A = 0.
        "tsuji" and "coeff_restitution" need the Hertz law (``normal_model="ring"``, f0 = 0). [-]
    damping_coefficient : float
        The DEM damping law's coefficient: eta_n0 [1/s] of "mass_velocity", eta_n0 [1/(m s)] of
        "viscoelastic", the restitution e in (0, 1] of "tsuji" and "coeff_restitution"; 0 with
        the paper's damping.
    tangential_stiffness : float or None
        k_t of the "linear_history" tangential law (LAMMPS's ``linear_history k_t``); None
        otherwise. [N/m]
    tangential_damping : float
        x_gamma,t of the DEM tangential laws: their tangential damping is x_gamma,t times the
        normal damping coefficient of ``damping_model`` (LAMMPS's convention); 0 by default. [-]
    rolling_model : {"torque", "lammps_sds"}
        Rolling resistance: "torque" (default) is the constant torque of ``rolling_friction``
        (none while it is 0, the paper's); "lammps_sds" LAMMPS's ``rolling sds k_roll gamma_roll
        mu_roll`` (:mod:`microimpact.model.dem_rolling`), with a DEM tangential law only. [-]
    rolling_stiffness : float or None
        k_roll of "lammps_sds"; None otherwise. [N/m]
    rolling_damping : float
        gamma_roll of "lammps_sds"; 0 by default. [N s/m]
    twisting_model : {"none", "lammps_sds", "lammps_marshall"}
        Twisting resistance with a DEM tangential law: "none" (default; LAMMPS's default too: the
        spin about the normal is kept), LAMMPS's ``twisting sds k_twist gamma_twist mu_twist`` or
        ``twisting marshall`` (coefficients from the tangential law, Marshall 2009;
        :mod:`microimpact.model.dem_twisting`). [-]
    twisting_stiffness : float or None
        k_twist of "lammps_sds"; None otherwise. [N m/rad]
    twisting_damping : float
        gamma_twist of "lammps_sds"; 0 by default. [N m s/rad]
    twisting_friction : float
        mu_twist of "lammps_sds", a length: the limit of the twisting torque is mu_twist F_n0; 0 by
        default. [m]

    Raises
    ------
    TypeError
        If a value is not a real number (a bool, None, a dict, an array, a text that is not a
        number). The message names the field.
    ValueError
        If a value is not finite, radius, density or stiffness is not positive, or f0, a zeta or
        the friction coefficient is negative; or if the values are so extreme together that a
        derived scale (mass, X, T, the solvers' impulse and energy units) under- or overflows the
        floating-point range. The message names the fields and the values.

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (1)-(15) and Table 1.

    Examples
    --------
    The paper's microsphere (Table 1 row 2): m = 4/3 pi r^3 rho, and the paper's laws by default:

    >>> c = Contact(radius=3.45e-6, density=1350.0, stiffness=1.776e9, adhesion_line_force=7.422)
    >>> f"{c.mass:.4e} kg", c.normal_model, c.tangential_model
    ('2.3221e-13 kg', 'ring', 'rigid')
    """

    radius: float
    density: float
    stiffness: float
    adhesion_line_force: float
    zeta_hertz: float = 0.0
    zeta_adhesion: float = 0.0
    friction: float = 0.0
    damping_reference_speed: float | None = None
    normal_model: str = "ring"
    tangential_model: str = "rigid"
    friction_model: str = "net"
    rolling_friction: float = 0.0
    shear_modulus: float | None = None
    damping_model: str = "paper"
    damping_coefficient: float = 0.0
    tangential_stiffness: float | None = None
    tangential_damping: float = 0.0
    rolling_model: str = "torque"
    rolling_stiffness: float | None = None
    rolling_damping: float = 0.0
    twisting_model: str = "none"
    twisting_stiffness: float | None = None
    twisting_damping: float = 0.0
    twisting_friction: float = 0.0

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name in SUB_MODELS:
                object.__setattr__(self, f.name, _sub_model(f.name, value))
                continue
            if f.name in _OPTIONAL and value is None:
                continue
            object.__setattr__(self, f.name, _as_number(f.name, value))
        for name in ("radius", "density", "stiffness"):
            check_positive(name, getattr(self, name))
        for name in ("adhesion_line_force", "zeta_hertz", "zeta_adhesion", "friction", "rolling_friction",
                     "damping_coefficient", "tangential_damping", "rolling_damping", "twisting_damping",
                     "twisting_friction"):
            _check_non_negative(name, getattr(self, name))
        for name in _OPTIONAL:
            if getattr(self, name) is not None:
                check_positive(name, getattr(self, name))
        if self.tangential_model not in ("rigid", "linear_history") and self.shear_modulus is None:
            raise ValueError(f"tangential_model={self.tangential_model!r} needs shear_modulus "
                             "(the effective shear modulus G* [Pa])")
        self._check_dem_tangential()
        self._check_dem_rolling()
        self._check_dem_twisting()
        self._check_damping_model()
        self._check_scales()

    def _check_dem_tangential(self) -> None:
        """The DEM tangential laws with their own parameters and LAMMPS's normal laws (model.dem_tangential)."""
        model = self.tangential_model
        dem = model in DEM_TANGENTIAL_MODELS
        if (model == "linear_history") != (self.tangential_stiffness is not None):
            raise ValueError("tangential_stiffness (k_t [N/m]) belongs to tangential_model='linear_history', and that "
                             f"law needs it: got tangential_model={model!r}, tangential_stiffness={self.tangential_stiffness!r}")
        if self.tangential_damping != 0.0 and not dem:
            raise ValueError(f"tangential_damping={self.tangential_damping!r} belongs to the DEM tangential laws "
                             f"({', '.join(map(repr, DEM_TANGENTIAL_MODELS))}), got tangential_model={model!r}")
        if not dem:
            return
        other = []
        if self.normal_model == "jkr":
            other.append("normal_model='jkr' (use 'jkr_force', LAMMPS's break)")
        if self.normal_model == "ring" and self.adhesion_line_force > 0.0:
            other.append(f"the ring adhesion force (adhesion_line_force={self.adhesion_line_force!r}; use 'jkr_force' or 'dmt')")
        other += [f"{n}={getattr(self, n)!r}" for n in ("zeta_hertz", "zeta_adhesion") if getattr(self, n) != 0.0]
        if self.rolling_model == "torque" and self.rolling_friction != 0.0:
            other.append(f"rolling_friction={self.rolling_friction!r} of the constant rolling torque (use "
                         "rolling_model='lammps_sds', LAMMPS's rolling resistance)")
        if self.friction_model != "net":
            other.append(f"friction_model={self.friction_model!r} (the limit is LAMMPS's own)")
        if other:
            raise ValueError(f"tangential_model={model!r} is LAMMPS's law and runs with LAMMPS's normal laws and "
                             f"damping only; not with {', '.join(other)}")

    def _check_dem_rolling(self) -> None:
        """LAMMPS's rolling law with its own parameters and a DEM tangential law (model.dem_rolling)."""
        sds = self.rolling_model in DEM_ROLLING_MODELS
        if sds != (self.rolling_stiffness is not None):
            raise ValueError("rolling_stiffness (k_roll [N/m]) belongs to rolling_model='lammps_sds', and that law "
                             f"needs it: got rolling_model={self.rolling_model!r}, rolling_stiffness={self.rolling_stiffness!r}")
        if self.rolling_damping != 0.0 and not sds:
            raise ValueError(f"rolling_damping={self.rolling_damping!r} (gamma_roll) belongs to rolling_model='lammps_sds', "
                             f"got rolling_model={self.rolling_model!r}")
        if sds and self.tangential_model not in DEM_TANGENTIAL_MODELS:
            raise ValueError(f"rolling_model={self.rolling_model!r} is LAMMPS's law and runs with its tangential laws "
                             f"({', '.join(map(repr, DEM_TANGENTIAL_MODELS))}), got tangential_model={self.tangential_model!r}")

    def _check_dem_twisting(self) -> None:
        """LAMMPS's twisting laws with their own parameters and a DEM tangential law (model.dem_twisting)."""
        model = self.twisting_model
        sds = model == "lammps_sds"
        if sds != (self.twisting_stiffness is not None):
            raise ValueError("twisting_stiffness (k_twist [N m/rad]) belongs to twisting_model='lammps_sds', and that "
                             f"law needs it: got twisting_model={model!r}, twisting_stiffness={self.twisting_stiffness!r}")
        for name in ("twisting_damping", "twisting_friction"):
            if getattr(self, name) != 0.0 and not sds:
                raise ValueError(f"{name}={getattr(self, name)!r} belongs to twisting_model='lammps_sds', "
                                 f"got twisting_model={model!r}")
        if model != "none" and self.tangential_model not in DEM_TANGENTIAL_MODELS:
            raise ValueError(f"twisting_model={model!r} is LAMMPS's law and runs with its tangential laws "
                             f"({', '.join(map(repr, DEM_TANGENTIAL_MODELS))}), got tangential_model={self.tangential_model!r}")

    def _check_damping_model(self) -> None:
        """One damping law at a time, with the normal laws it is defined for (model.dem_damping)."""
        model, coef = self.damping_model, self.damping_coefficient
        if model == "paper":
            if coef != 0.0:
                raise ValueError(f"damping_coefficient={coef!r} belongs to a DEM damping_model; the paper's damping "
                                 "(damping_model='paper') is set by zeta_hertz and zeta_adhesion")
            return
        paper = [f"{n}={getattr(self, n)!r}" for n in ("zeta_hertz", "zeta_adhesion") if getattr(self, n) != 0.0]
        if self.damping_reference_speed is not None:
            paper.append(f"damping_reference_speed={self.damping_reference_speed!r}")
        if paper:
            raise ValueError(f"damping_model={model!r} replaces the paper's damping: {', '.join(paper)} must be unset (0)")
        hertz = self.normal_model == "ring" and self.adhesion_line_force == 0.0
        if model in ("tsuji", "coeff_restitution"):
            if not 0.0 < coef <= 1.0:
                raise ValueError(f"damping_coefficient={coef!r} is the restitution of damping_model={model!r} and "
                                 "must lie in (0, 1]")
            if not hertz:
                raise ValueError(f"damping_model={model!r} is defined for the Hertz law only (as in LAMMPS, no "
                                 f"cohesion): normal_model='ring' with adhesion_line_force=0, got "
                                 f"normal_model={self.normal_model!r}, adhesion_line_force={self.adhesion_line_force!r}")
        elif self.normal_model == "ring" and not hertz:
            raise ValueError(f"damping_model={model!r} with the ring adhesion force (adhesion_line_force="
                             f"{self.adhesion_line_force!r}) is not implemented: use normal_model 'jkr_force', 'jkr' "
                             "or 'dmt', or the paper's damping")

    def _check_scales(self) -> None:
        """The derived scales the solvers divide by are finite normal doubles (check_representable)."""
        r, rho, k, f0 = self.radius, self.density, self.stiffness, self.adhesion_line_force
        size = f"radius={r!r}, density={rho!r}"
        with np.errstate(all="ignore"):
            try:
                check_representable("mass (4/3) pi r^3 rho [kg]", self.mass, size)
                check_representable("moment of inertia (2/5) m r^2 [kg m^2]", self.moment_of_inertia, size)
                check_representable("damping speed scale (r^3 K / m)^(2/5)", self.damping_speed_scale,
                                    f"radius={r!r}, density={rho!r}, stiffness={k!r}")
                if f0 > 0.0:
                    every = f"radius={r!r}, density={rho!r}, stiffness={k!r}, adhesion_line_force={f0!r}"
                    x, t = self.length_scale, self.time_scale
                    check_representable("length scale X = 2 pi f0 / K [m]", x, f"stiffness={k!r}, adhesion_line_force={f0!r}")
                    check_representable("time scale T [s]", t, every)
                    u = x / t
                    check_representable("speed scale X / T [m/s]", u, every)
                    check_representable("impulse unit m X / T [N s]", self.mass * u, every)
                    check_representable("energy unit m (X / T)^2 [J]", self.mass * u * u, every)
                    check_representable("twist impulse unit m X / T sqrt(r X) [N m s]",
                                        self.mass * u * math.sqrt(r * x), every)
            except (OverflowError, ZeroDivisionError):
                raise ValueError(f"radius={r!r}, density={rho!r}, stiffness={k!r}, adhesion_line_force={f0!r}: "
                                 "a derived scale leaves the floating-point range") from None

    # ----------------------------------------------------------------- constructors
    @classmethod
    def from_elastic(
        cls,
        radius: float,
        density: float,
        youngs_modulus_sphere: float,
        poisson_sphere: float,
        youngs_modulus_surface: float,
        poisson_surface: float,
        adhesion_line_force: float | None = None,
        *,
        work_of_adhesion: float | None = None,
        **kwargs,
    ) -> "Contact":
        """Build a contact from Young's moduli and Poisson ratios, Eqs. (3)-(4).

        Parameters
        ----------
        youngs_modulus_sphere, youngs_modulus_surface : float
            Young's moduli E1, E2. [Pa]
        poisson_sphere, poisson_surface : float
            Poisson ratios nu1, nu2, each in (-1, 0.5). [-]
        adhesion_line_force : float, optional
            f0. [N/m] Give this or ``work_of_adhesion``; neither means no adhesion.
        work_of_adhesion : float, optional
            Dupre work of adhesion w_A; f0 then follows from Eq. (7). [J/m^2]
        **kwargs
            Other :class:`Contact` fields (zetas, friction, damping_reference_speed).
        """
        check_positive("youngs_modulus_sphere", youngs_modulus_sphere)
        check_positive("youngs_modulus_surface", youngs_modulus_surface)
        _check_poisson("poisson_sphere", poisson_sphere)
        _check_poisson("poisson_surface", poisson_surface)
        stiffness = stiffness_from_elastic(
            youngs_modulus_sphere, poisson_sphere, youngs_modulus_surface, poisson_surface
        )
        if adhesion_line_force is not None and work_of_adhesion is not None:
            raise ValueError("give adhesion_line_force or work_of_adhesion, not both")
        if work_of_adhesion is not None:
            return cls.from_work_of_adhesion(radius, density, stiffness, work_of_adhesion, **kwargs)
        return cls(radius, density, stiffness, adhesion_line_force or 0.0, **kwargs)

    @classmethod
    def from_work_of_adhesion(
        cls, radius: float, density: float, stiffness: float, work_of_adhesion: float, **kwargs
    ) -> "Contact":
        """Build a contact whose f0 follows from the work of adhesion w_A, Eq. (7).

        Parameters
        ----------
        work_of_adhesion : float
            Dupre work of adhesion w_A = gamma_1 + gamma_2 - gamma_12. [J/m^2]
        """
        check_positive("radius", radius)
        check_positive("stiffness", stiffness)
        _check_non_negative("work_of_adhesion", work_of_adhesion)
        f0 = adhesion_line_force_from_work(stiffness, radius, work_of_adhesion)
        return cls(radius, density, stiffness, f0, **kwargs)

    def with_(self, **changes) -> "Contact":
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)

    def at_radius(self, radius: float, **changes) -> "Contact":
        """The same materials with a sphere of another radius: f0 follows the radius, Eq. (7).

        The work of adhesion w_A is the material property shared by all sizes, so f0 scales as
        r^(1/3) (model notes, section 1); the damping coefficients, density, stiffness and
        friction are kept unless given in ``changes``.

        Parameters
        ----------
        radius : float
            The new sphere radius. [m]
        **changes
            Other fields to change.
        """
        check_positive("radius", radius)
        f0 = adhesion_line_force_from_work(self.stiffness, radius, self.work_of_adhesion)
        return replace(self, radius=float(radius), adhesion_line_force=f0, **changes)

    # ----------------------------------------------------------------- derived
    # (cached: a frozen contact's derived scales never change, and a single impact reads them often)
    @cached_property
    def mass(self) -> float:
        """Sphere mass m = (4/3) pi r^3 rho. [kg]"""
        return 4.0 / 3.0 * math.pi * self.radius**3 * self.density

    @cached_property
    def moment_of_inertia(self) -> float:
        """Centroidal moment of inertia of a homogeneous sphere, I = (2/5) m r^2. [kg m^2]"""
        return 0.4 * self.mass * self.radius**2

    @cached_property
    def work_of_adhesion(self) -> float:
        """Work of adhesion w_A that gives this f0 through Eq. (7). [J/m^2]"""
        return math.sqrt(2.0 * math.pi * self.adhesion_line_force**3 / (9.0 * self.stiffness * self.radius))

    @cached_property
    def length_scale(self) -> float:
        """X = 2 pi f0 / K, Eq. (29): the static equilibrium penetration. [m]"""
        return 2.0 * math.pi * self.adhesion_line_force / self.stiffness

    @cached_property
    def time_scale(self) -> float:
        """T = sqrt(m / sqrt(2 pi r f0 K)), Eq. (30) corrected (printed as T^2). [s]"""
        return math.sqrt(self.mass / math.sqrt(2.0 * math.pi * self.radius * self.adhesion_line_force * self.stiffness))

    @cached_property
    def damping_speed_scale(self) -> float:
        """Speed scale (r^3 K / m)^(2/5) of Eqs. (14)-(15) without the sqrt(v_n) factor. [(m/s)^(4/5)]"""
        return (self.radius**3 * self.stiffness / self.mass) ** 0.4

    def reference_speed(self, normal_speed: float) -> float:
        """The damping reference speed v_n used for an impact with this incident normal speed. [m/s]"""
        return normal_speed if self.damping_reference_speed is None else self.damping_reference_speed

    def damping_coefficients(self, normal_speed: float) -> tuple[float, float]:
        """Dimensional damping coefficients (C_H, C_A), Eqs. (14)-(15). [s/m]

        Parameters
        ----------
        normal_speed : float or numpy.ndarray
            Incident normal speed of the impact; used as v_n unless a fixed
            ``damping_reference_speed`` is set. [m/s]
        """
        v = self.reference_speed(normal_speed)
        if isinstance(v, np.ndarray):
            if not np.all(np.isfinite(v) & (v > 0.0)):
                raise ValueError(f"damping reference speed must be finite and > 0, got {v[~(v > 0.0)].ravel()[:1]}")
        else:
            check_positive("damping reference speed", v)
        scale = self.damping_speed_scale * v**0.2  # (r^3 K sqrt(v) / m)^(2/5)
        return self.zeta_hertz / scale, self.zeta_adhesion / scale

    def nondimensional_damping(self, normal_speed: float) -> tuple[float, float]:
        """(C1, C2) = (C_H, C_A) X / T, Eqs. (31)-(32). [-]"""
        c_h, c_a = self.damping_coefficients(normal_speed)
        u = self.length_scale / self.time_scale
        return c_h * u, c_a * u


def stiffness_from_elastic(e1: float, nu1: float, e2: float, nu2: float) -> float:
    """Effective stiffness K = 4 / (3 pi (k1 + k2)), k_i = (1 - nu_i^2) / (pi E_i), Eqs. (3)-(4). [Pa]"""
    k1 = (1.0 - nu1**2) / (math.pi * e1)
    k2 = (1.0 - nu2**2) / (math.pi * e2)
    return 4.0 / (3.0 * math.pi * (k1 + k2))


def adhesion_line_force_from_work(stiffness: float, radius: float, work_of_adhesion: float) -> float:
    """Adhesion line force f0 = (9/(2 pi) K r w_A^2)^(1/3), Eq. (7). [N/m]

    Eq. (7) equates the Brach-Dunn equilibrium contact radius with the JKR zero-load radius.
    """
    return (9.0 / (2.0 * math.pi) * stiffness * radius * work_of_adhesion**2) ** (1.0 / 3.0)

