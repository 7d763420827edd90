"""Public impact API: one impact (:func:`simulate_impact`) or a broadcast batch (:func:`simulate_many`).

Both return the one result type: :class:`~microimpact.model.kinematics.ImpactResult` for one impact,
an xarray Dataset of its fields for a batch. ``simulate_impact(..., method=...)`` selects the solver:
``"engine"`` (one compiled normal solve plus the closed-form tangential map), ``"reference"`` (the
full 3-D scipy integration) or ``"rkg"`` (the paper's fixed-step Runge-Kutta-Gill normal solve plus
the same tangential map). ``simulate_many`` runs the engine only: one normal solve per distinct
normal speed serves every angle, spin and friction coefficient that shares it.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import sys
from collections.abc import Mapping
from typing import TYPE_CHECKING

import numpy as np

from microimpact.io.provenance import contact_attributes
from microimpact.io.variables import attributes
from microimpact.model.adhesion_models import check_adhesion_regime, tabor_parameter
from microimpact.solvers import DEFAULT_RTOL, METHODS, MIN_RTOL, check_rtol, check_sub_models, engine
from microimpact.solvers.family import (FAMILY_MIN_SPEEDS, NODE_RTOL_FLOOR, FamilyBudgetExceeded, normal_family,
                                       normal_speed_range)
from microimpact.solvers.rkg import DEFAULT_STEPS, solve_normal_rkg
from microimpact.model.contact import Contact
from microimpact.model.law import contact_potential_energy, nondimensional_scales
from microimpact.model.coefficients import coefficients_kernel, impact_coefficients
from microimpact.model.kinematics import ImpactResult, incident_velocity, slip_velocity
from microimpact.model.tangential import _sliding_impulse, _twist_stop, stop_impulses, tangential_kernel, tangential_outcome

if TYPE_CHECKING:  # xarray is imported by the batch functions only: one simulate_impact starts faster
    import xarray as xr

__all__ = ["simulate_impact", "simulate_many", "check_rtol", "RESULT_VARIABLES", "MIN_RTOL", "FAMILY_MIN_SPEEDS"]

#: the variables that simulate_many returns (units and long names in microimpact.io.variables)
RESULT_VARIABLES: tuple[str, ...] = (
    "outcome", "e_n", "mu_t", "mu_tp", "K_L", "K_t", "velocity_out_n", "velocity_out_t",
    "velocity_out_tp", "omega_out_n", "omega_out_t", "omega_out_tp", "contact_time",
    "max_penetration", "slip_ended", "friction_impulse", "dissipated_energy", "not_determined",
)


def _real_array(name: str, value) -> np.ndarray:
    """``value`` as a float array; TypeError naming ``name`` if it is not real numbers (text, a
    dict, None, bools, complex), ValueError if it is a ragged sequence."""
    xarray = sys.modules.get("xarray")  # a DataArray exists only once xarray is imported
    if xarray is not None and isinstance(value, xarray.DataArray):
        value = value.values
    if value is None or isinstance(value, (str, bytes, bool, dict, set)):
        raise TypeError(f"{name} must be a real number or an array of them, got {type(value).__name__} {value!r}")
    try:
        a = np.asarray(value)
    except (ValueError, TypeError) as exc:
        raise ValueError(f"{name} must be a rectangular array of real numbers ({exc})") from None
    if a.dtype.kind == "O":
        try:
            a = a.astype(float)
        except (ValueError, TypeError):
            raise TypeError(f"{name} must be real numbers, got {value!r}") from None
    if a.dtype.kind not in "iuf":
        raise TypeError(f"{name} must be real numbers, got an array of dtype {a.dtype} ({value!r})")
    return a.astype(float, copy=False)


def _real_scalar(name: str, value) -> float:
    """``float(value)`` for one real number; an array gets a TypeError that points to simulate_many."""
    if type(value) is float or type(value) is int:  # the common case, without numpy
        return float(value)
    a = _real_array(name, value)
    if a.ndim != 0:
        raise TypeError(f"{name} must be one number in simulate_impact, got an array of shape {a.shape}; "
                        "for a batch of impacts use simulate_many")
    return float(a)


def _check_call(contact, rtol) -> float:
    """The contact's type and rtol (finite, 0 < rtol < 1): TypeError / ValueError naming them."""
    if type(rtol) is float and MIN_RTOL <= rtol < 1.0 and isinstance(contact, Contact):
        return rtol  # the common case, without the ABC checks (a single call costs microseconds)
    if not isinstance(contact, Contact):
        hint = "; for a mapping of fields use Contact(**contact)" if isinstance(contact, Mapping) else ""
        raise TypeError(f"contact must be a microimpact Contact, got {type(contact).__name__}{hint}")
    return check_rtol(rtol)


def _check_omega(omega) -> tuple:
    if type(omega) is tuple and len(omega) == 3:
        return omega
    if isinstance(omega, (str, bytes, Mapping)) or not hasattr(omega, "__len__"):
        raise TypeError(f"omega must be a sequence of 3 components (omega_n, omega_t, omega_tp), "
                        f"got {type(omega).__name__} {omega!r}")
    if len(omega) != 3:
        raise ValueError(f"omega must have 3 components (omega_n, omega_t, omega_tp), got {omega!r}")
    return tuple(omega)


#: The types of the scalar fast paths (exact types: a numpy scalar takes the general path)
_FLOATS = frozenset((float,))


def _check_inputs(speed, incidence_deg, azimuth_deg, omega):
    if _FLOATS.issuperset((type(speed), type(incidence_deg), type(azimuth_deg), *map(type, omega))):
        w_n, w_t, w_tp = omega
        if 0.0 < speed < math.inf and 0.0 <= incidence_deg < 90.0 and math.isfinite(azimuth_deg) \
                and math.isfinite(w_n) and math.isfinite(w_t) and math.isfinite(w_tp):
            return  # the common scalar case, valid (the array checks below give the messages)
    speed = np.asarray(speed, dtype=float)
    inc = np.asarray(incidence_deg, dtype=float)
    if not np.all(np.isfinite(speed)) or np.any(speed <= 0.0):
        raise ValueError(f"speed must be finite and > 0 m/s, got {float(speed[~(np.isfinite(speed) & (speed > 0))].ravel()[0])!r}")
    if not np.all(np.isfinite(inc)) or np.any((inc < 0.0) | (inc >= 90.0)):
        raise ValueError(f"incidence_deg must lie in [0, 90) deg, got {float(inc[~(np.isfinite(inc) & (inc >= 0) & (inc < 90))].ravel()[0])!r}")
    if not np.all(np.isfinite(np.asarray(azimuth_deg, dtype=float))):
        raise ValueError(f"azimuth_deg must be finite, got {azimuth_deg!r}")
    for name, w in zip(("omega_n", "omega_t", "omega_tp"), omega):
        if not np.all(np.isfinite(np.asarray(w, dtype=float))):
            raise ValueError(f"{name} must be finite, got {w!r}")


_TINY = sys.float_info.min


def _scalar_scales_ok(contact, speed, incidence_deg, omega) -> bool:
    """The common case of :func:`_check_scales` in plain floats: one impact whose scales are all
    comfortably inside the floating-point range (False sends it to the full check)."""
    if not (isinstance(speed, float) and isinstance(incidence_deg, float) and contact.adhesion_line_force > 0.0):
        return False
    v_n = speed * math.cos(math.radians(incidence_deg))
    kinetic = 0.5 * contact.mass * speed * speed
    energy = kinetic + 0.5 * contact.moment_of_inertia * (omega[0] * omega[0] + omega[1] * omega[1] + omega[2] * omega[2])
    return 1e-250 < speed * speed < 1e300 and 1e-250 < kinetic and 1e-250 < v_n and math.isfinite(energy)


def _extreme_scales_ok(contact, speed, incidence_deg, omega) -> bool:
    """The common case of :func:`_check_scales` for a batch: every checked quantity is monotonic
    in the speed, the cosine of the incidence and the spins, so the batch is fine when its extreme
    corners are (seven reductions instead of a dozen temporaries of the batch's size; False sends
    it to the full check, which names the culprit)."""
    v = np.asarray(speed, dtype=float)
    if v.size < 2:
        return False
    inc = np.asarray(incidence_deg, dtype=float)
    cos_lo, cos_hi = math.cos(math.radians(float(inc.max()))), math.cos(math.radians(float(inc.min())))
    v_lo, v_hi = float(v.min()), float(v.max())
    spin = sum(float(np.max(np.abs(np.asarray(w, dtype=float)))) ** 2 for w in omega)
    corners = [(v_lo, v_lo * cos_lo, 0.0), (v_hi, v_hi * cos_hi, spin)]
    return all(_scalar_scales_ok(contact, sp, 0.0, (0.0, 0.0, 0.0)) and 1e-250 < v_n
               and math.isfinite(0.5 * contact.mass * sp * sp + 0.5 * contact.moment_of_inertia * w2)
               for sp, v_n, w2 in corners)


def _check_scales(contact, speed, incidence_deg, omega) -> None:
    """The speed-dependent quantities the solvers and Eqs. (21)-(25) divide by are finite normal
    doubles: v^2 and m v^2, the normal speed, the Hertz scales of an impact without adhesion, and
    the incident energy with the spin. ValueError naming the argument (speed, omega_*) otherwise:
    ``speed=1e-300`` would give v^2 = 0 and a ZeroDivisionError in K_L."""
    if _scalar_scales_ok(contact, speed, incidence_deg, omega) or _extreme_scales_ok(contact, speed, incidence_deg, omega):
        return
    with np.errstate(all="ignore"):
        v = np.asarray(speed, dtype=float)
        v_n = v * np.cos(np.radians(np.asarray(incidence_deg, dtype=float)))
        m, inertia = contact.mass, contact.moment_of_inertia

        def bad(x):
            x = np.asarray(x, dtype=float)
            return ~(np.isfinite(x) & (np.abs(x) >= _TINY))

        for what, q in (("v^2 [m^2/s^2]", v * v), ("the kinetic energy m v^2 / 2 [J]", 0.5 * m * v * v),
                        ("the normal speed v cos(incidence) [m/s]", v_n)):
            q, vv = np.broadcast_arrays(np.asarray(q, dtype=float), v)
            b = bad(q)
            if np.any(b):
                i = np.flatnonzero(b.ravel())[0]
                raise ValueError(f"speed={float(vv.ravel()[i])!r} m/s: {what} is {float(q.ravel()[i])!r}, "
                                 "outside the floating-point range; give a speed whose square and kinetic "
                                 "energy are finite normal numbers")
        energy = 0.5 * m * v * v + 0.5 * inertia * sum(np.square(np.asarray(w, dtype=float)) for w in omega)
        if not np.all(np.isfinite(energy)):
            raise ValueError("omega_n, omega_t, omega_tp: the incident kinetic energy with this spin overflows "
                             "the floating-point range; give a smaller spin")
        if contact.adhesion_line_force == 0.0:  # Hertz scales depend on the speed
            sc = nondimensional_scales(contact, v_n)
            u = sc.length / sc.time
            for what, q in (("Hertz length scale [m]", sc.length), ("Hertz time scale [s]", sc.time),
                            ("impulse unit [N s]", m * u), ("energy unit [J]", m * u * u),
                            ("twist impulse unit [N m s]", m * u * np.sqrt(contact.radius * sc.length))):
                if np.any(bad(q)):
                    raise ValueError(f"speed: the derived {what} of an impact without adhesion is outside "
                                     f"the floating-point range for this speed and contact "
                                     f"(radius={contact.radius!r}, stiffness={contact.stiffness!r})")


def simulate_impact(contact, speed, incidence_deg=0.0, azimuth_deg=0.0, omega=(0.0, 0.0, 0.0), *,
                    rtol: float = DEFAULT_RTOL, method: str = "engine", steps: int | None = None) -> ImpactResult:
    """Simulate one impact of a sphere on the flat surface.

    Parameters
    ----------
    contact : Contact
    speed : float
        Magnitude of the incident velocity. [m/s]
    incidence_deg : float
        Incidence angle from the surface normal, in [0, 90). [deg]
    azimuth_deg : float
        Direction of the tangential velocity in the (t, t') plane. [deg]
    omega : tuple of 3 float
        Initial spin (omega_n, omega_t, omega_t'). [rad/s]
    rtol : float
        Relative tolerance of the integration ("engine" and "reference"). [-]
    method : {"engine", "reference", "rkg"}
        ``"engine"`` (default): the compiled normal solve plus the closed-form tangential map.
        ``"reference"``: the full 3-D scipy integration (:mod:`microimpact.solvers.reference`).
        ``"rkg"``: the paper's fixed-step Runge-Kutta-Gill normal solve
        (:func:`microimpact.solvers.rkg.solve_normal_rkg`), then the same tangential map.
    steps : int, optional
        ``"rkg"`` only: steps per estimated contact duration (default
        :data:`microimpact.solvers.rkg.DEFAULT_STEPS`, e_n to about 1e-6). [-]

    Returns
    -------
    ImpactResult

    Raises
    ------
    TypeError
        For a ``contact`` that is not a :class:`Contact`, or an input that is not a real number
        (an array ``speed``: use :func:`simulate_many`). The message names the argument.
    ValueError
        For bad values (not finite, out of range, rtol outside (0, 1), a speed whose v^2 or kinetic
        energy leaves the floating-point range) or an unknown method; for ``steps`` with a method other than "rkg"; and for
        "rkg" when the sphere is captured while the tangential outcome is needed (friction with
        slip or twist): the RKG stops at the capture test and does not follow the captured
        oscillation whose friction impulse the map needs (use "engine" or "reference").

    References
    ----------
    Cheng, Brach & Dunn (2002)

    Dormand & Prince (1980)

    Hairer, Norsett & Wanner (1993), Secs. II.5-II.6

    Examples
    --------
    An undamped, non-adhesive Hertz sphere rebounds with e_n = 1; with friction 0.2 at 60 deg it
    slides throughout, and the tangential impulse ratio is -f (Eq. (22)):

    >>> from microimpact.model.contact import Contact
    >>> c = Contact(3.45e-6, 1350.0, 1.776e9, 0.0)
    >>> simulate_impact(c, 1.0, 0.0).e_n
    1.0
    >>> r = simulate_impact(c.with_(friction=0.2), 1.0, 60.0)
    >>> r.outcome, round(r.mu_t, 6)
    ('rebound', -0.2)
    """
    rtol, speed, incidence_deg, azimuth_deg, omega = _checked_impact(contact, speed, incidence_deg, azimuth_deg,
                                                                     omega, rtol, method, steps)
    if method == "engine" and _needs_coupled(contact):
        v_in = incident_velocity(float(speed), float(incidence_deg), float(azimuth_deg))
        res = _coupled_results(contact, tuple(np.array([x]) for x in v_in), tuple(np.array([w]) for w in omega),
                               np.array([contact.friction]), rtol)
        return _coupled_impact_result(contact, v_in, omega, res)
    normal = _normal_solver(contact)
    if method == "reference" and contact.damping_model == "paper" and (contact.normal_model == "ring"
                                                                       or contact.adhesion_line_force == 0.0):
        # imported here: scipy.integrate costs ~0.7 s of import time that the engine never needs
        from microimpact.solvers.reference import simulate_reference

        # without adhesion JKR and DMT are the Hertz law of the paper's model
        return simulate_reference(contact.with_(normal_model="ring"), speed, incidence_deg, azimuth_deg, omega, rtol=rtol)
    v_in = incident_velocity(float(speed), float(incidence_deg), float(azimuth_deg))
    w_in = tuple(float(w) for w in omega)
    u_t, u_tp = slip_velocity(contact.radius, v_in[1], v_in[2], w_in[1], w_in[2])
    slip = math.hypot(u_t, u_tp)
    needs_tangential = contact.friction > 0.0 and (slip > 0.0 or w_in[0] != 0.0)
    sol = _normal_solve(contact, normal, v_in, w_in, slip, needs_tangential, speed, rtol, method, steps)
    return _impact_result(contact, v_in, w_in, sol, slip, method, needs_tangential)


def _checked_impact(contact, speed, incidence_deg, azimuth_deg, omega, rtol, method, steps) -> tuple:
    """(rtol, speed, incidence_deg, azimuth_deg, omega) of :func:`simulate_impact`, each checked
    (TypeError or ValueError naming the argument), and the method, ``steps`` and the contact's
    sub-models checked against each other."""
    rtol = _check_call(contact, rtol)
    omega = _check_omega(omega)
    speed = _real_scalar("speed", speed)
    incidence_deg = _real_scalar("incidence_deg", incidence_deg)
    azimuth_deg = _real_scalar("azimuth_deg", azimuth_deg)
    if not _FLOATS.issuperset(map(type, omega)):
        omega = tuple(_real_scalar(name, w) for name, w in zip(("omega_n", "omega_t", "omega_tp"), omega))
    _check_inputs(speed, incidence_deg, azimuth_deg, omega)
    _check_scales(contact, speed, incidence_deg, omega)
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(map(repr, METHODS))}, got {method!r}")
    if steps is not None and method != "rkg":
        raise ValueError(f"steps applies to method='rkg' only, got method={method!r}")
    if steps is not None and (isinstance(steps, bool) or not isinstance(steps, numbers.Integral) or steps < 1):
        raise ValueError(f"steps must be a whole number >= 1, got {steps!r}")
    check_sub_models(contact, method)
    return rtol, speed, incidence_deg, azimuth_deg, omega


def _normal_solve(contact, normal, v_in, w_in, slip, needs_tangential, speed, rtol, method, steps):
    """The normal solution of one impact by ``method`` ("rkg", "reference": the scipy integration of
    a JKR or DMT law, else the engine), followed as far as the tangential map needs (the sliding
    and twist impulses of slip speed ``slip`` [m/s] and spin ``w_in``) where ``needs_tangential``;
    ``normal`` is the module of the contact's normal law (:func:`_normal_solver`)."""
    j_star = _sliding_impulse(contact.mass, contact.friction, slip)
    j_target = j_star if needs_tangential and 0.0 < j_star < math.inf else None
    if method == "rkg":
        sol = solve_normal_rkg(contact, -v_in[0], steps=DEFAULT_STEPS if steps is None else steps,
                               friction_impulse_target=j_target)
        if sol.outcome == "capture" and needs_tangential:
            raise ValueError(
                "method='rkg' stops a captured impact at the capture test (E < 0) and does not follow "
                "the captured oscillation, whose friction impulse the tangential outcome needs "
                f"(speed {speed!r} m/s, friction {contact.friction!r}); use method='engine' or 'reference'")
    elif method == "reference":  # JKR or DMT: the scipy integration of their normal law, then the map
        sol = normal.solve_normal_reference(
            contact, -v_in[0], rtol=min(rtol, 1e-10), need_tail=needs_tangential, friction_impulse_stop=j_star,
            twist_impulse_stop=_twist_stop(contact.moment_of_inertia, contact.friction, w_in[0]))
    else:
        sol = normal.solve_normal(
            contact, -v_in[0], rtol=rtol, need_tail=needs_tangential, friction_impulse_target=j_target,
            friction_impulse_stop=j_star,
            twist_impulse_stop=_twist_stop(contact.moment_of_inertia, contact.friction, w_in[0]),
        )
    return sol


def _impact_result(contact, v_in, w_in, sol, slip, method, needs_tangential) -> ImpactResult:
    """The ImpactResult of a normal solve (engine or RKG) and the closed-form tangential map."""
    m, inertia, r = contact.mass, contact.moment_of_inertia, contact.radius
    tan = tangential_kernel(m, inertia, r, contact.friction, v_in[1], v_in[2], *w_in, sol.friction_impulse,
                            sol.twist_impulse)
    captured = sol.outcome == "capture"
    v_out = (0.0 if captured else sol.e_n * -v_in[0], tan[0], tan[1])
    w_out = (tan[2], tan[3], tan[4])
    e_n, mu_t, mu_tp, k_l, k_t = coefficients_kernel(m, inertia, *v_in, *w_in, *v_out, *w_out, captured)
    slip_ended = bool(tan[5])
    return ImpactResult(
        outcome=sol.outcome,
        e_n=e_n, mu_t=mu_t, mu_tp=mu_tp, K_L=k_l, K_t=k_t,
        velocity_in=v_in,
        omega_in=w_in,
        velocity_out=v_out,
        omega_out=w_out,
        contact_time=sol.contact_time,
        capture_time=sol.capture_time,
        max_penetration=sol.max_penetration,
        slip_ended=slip_ended,
        slip_end_time=(0.0 if slip == 0.0 else sol.slip_end_time) if slip_ended else math.nan,
        friction_impulse=sol.friction_impulse,
        dissipated_energy=(float(_normal_dissipation(contact, -v_in[0], True, 0.0)) if captured
                           else sol.dissipated_energy) + tan[7],
        final_contact_energy=settled_contact_energy(contact) if captured else 0.0,
        method=method,
        stop_reason="separation" if not captured else ("settled" if needs_tangential else "capture"),
    )


def _needs_coupled(contact) -> bool:
    """Whether the contact selects a sub-model that the closed-form map alone does not cover."""
    return contact.tangential_model != "rigid" or contact.friction_model != "net"


def _dem_tangential_batch(contact, v_in, w_in, f, rtol) -> dict:
    """:func:`microimpact.solvers.dem_tangential.solve_dem_tangential` over a batch, in the coupled
    solver's result form (one impact at a time: it integrates in Python)."""
    from microimpact.solvers.dem_tangential import solve_dem_tangential

    n = np.broadcast(*v_in, *w_in, f).size
    v_in, w_in = ([np.broadcast_to(x, (n,)) for x in group] for group in (v_in, w_in))
    f = np.broadcast_to(f, (n,))
    names = ("e_n", "v_t", "v_tp", "omega_n", "omega_t", "omega_tp", "contact_time", "capture_time",
             "slip_end_time", "max_penetration", "friction_impulse")
    out = {k: np.empty(n) for k in names}
    out["captured"] = np.empty(n, dtype=bool)
    out["slip_ended"] = np.empty(n, dtype=bool)
    for i in range(n):
        one = contact if f[i] == contact.friction else contact.with_(friction=float(f[i]))
        r = solve_dem_tangential(one, tuple(float(x[i]) for x in v_in), tuple(float(w[i]) for w in w_in), rtol=rtol)
        out["captured"][i] = r.captured
        out["e_n"][i] = r.e_n
        out["v_t"][i], out["v_tp"][i] = r.state["velocity_out"][1:]
        out["omega_n"][i], out["omega_t"][i], out["omega_tp"][i] = r.state["omega_out"]
        out["contact_time"][i], out["capture_time"][i] = r.contact_time, r.capture_time
        out["max_penetration"][i], out["friction_impulse"][i] = r.max_penetration, r.friction_impulse
        out["slip_ended"][i], out["slip_end_time"][i] = r.state["slip_ended"], r.slip_end_time
    return out


def _coupled_results(contact, v_in, w_in, f, rtol) -> dict:
    """The batch results (as :func:`_solve_batch`) of the compiled coupled solver, or of the DEM
    tangential laws' solver (:mod:`microimpact.solvers.dem_tangential`)."""
    from microimpact.solvers.coupled import solve_coupled
    from microimpact.solvers.dem_tangential import uses_dem_tangential

    m, inertia = contact.mass, contact.moment_of_inertia
    c = (_dem_tangential_batch if uses_dem_tangential(contact) else solve_coupled)(contact, v_in, w_in, f, rtol=rtol)
    captured = c["captured"]
    vn_out = np.where(captured, 0.0, -c["e_n"] * v_in[0])
    v_out = (vn_out, c["v_t"], c["v_tp"])
    w_out = (c["omega_n"], c["omega_t"], c["omega_tp"])
    coef = impact_coefficients(m, inertia, v_in, w_in, v_out, w_out, captured)
    kinetic = lambda v, w: 0.5 * m * sum(np.square(x) for x in v) + 0.5 * inertia * sum(np.square(x) for x in w)
    settled = settled_contact_energy(contact) if contact.adhesion_line_force > 0 else 0.0
    return {
        "outcome": captured.astype(np.int8), "e_n": c["e_n"], **{k: coef[k] for k in ("mu_t", "mu_tp", "K_L", "K_t")},
        "velocity_out_n": vn_out, "velocity_out_t": c["v_t"], "velocity_out_tp": c["v_tp"],
        "omega_out_n": c["omega_n"], "omega_out_t": c["omega_t"], "omega_out_tp": c["omega_tp"],
        "contact_time": c["contact_time"], "max_penetration": c["max_penetration"],
        "slip_ended": c["slip_ended"].astype(np.int8), "friction_impulse": c["friction_impulse"],
        # everything the sphere lost: kinetic energy in - out, less the contact energy it keeps when captured
        "dissipated_energy": kinetic(v_in, w_in) - kinetic(v_out, w_out) - np.where(captured, settled, 0.0),
        "capture_time": c["capture_time"], "slip_end_time": c["slip_end_time"],
        "tangential_error": c.get("tangential_error", np.zeros(captured.size)),
        "not_determined": c.get("not_determined", np.zeros(captured.size, dtype=bool)),
    }


def _coupled_impact_result(contact, v_in, w_in, res) -> ImpactResult:
    """The ImpactResult of one impact of the coupled solver."""
    from microimpact.solvers.coupled import stops_at_capture
    from microimpact.solvers.dem_tangential import uses_dem_tangential

    one = {k: (v.item() if isinstance(v, np.ndarray) else v) for k, v in res.items()}
    captured = bool(one["outcome"])
    return ImpactResult(
        outcome="capture" if captured else "rebound",
        **{k: float(one[k]) for k in ("e_n", "mu_t", "mu_tp", "K_L", "K_t")},
        velocity_in=tuple(float(x) for x in v_in), omega_in=tuple(float(w) for w in w_in),
        velocity_out=(float(one["velocity_out_n"]), float(one["velocity_out_t"]), float(one["velocity_out_tp"])),
        omega_out=(float(one["omega_out_n"]), float(one["omega_out_t"]), float(one["omega_out_tp"])),
        contact_time=float(one["contact_time"]), capture_time=float(one["capture_time"]),
        max_penetration=float(one["max_penetration"]), slip_ended=bool(one["slip_ended"]),
        slip_end_time=float(one["slip_end_time"]), friction_impulse=float(one["friction_impulse"]),
        dissipated_energy=float(one["dissipated_energy"]),
        final_contact_energy=settled_contact_energy(contact) if captured else 0.0,
        method=(f"engine:dem_tangential ({contact.tangential_model}"
                + (f", twisting {contact.twisting_model})" if contact.twisting_model != "none" else ")")
                if uses_dem_tangential(contact)
                else f"engine:coupled ({contact.tangential_model}, {contact.friction_model})"),
        stop_reason="separation" if not captured else "capture" if (stops_at_capture(contact) or uses_dem_tangential(contact)) else "settled",
        not_determined=(f"final tangential velocity and spin (error estimate {float(one['tangential_error']):.3g} m/s: "
                        "the rolling torque reverses with the held contact's vibration)" if one["not_determined"] else ""),
    )


def _normal_solver(contact):
    """The module that solves the contact's normal law: the paper's engine for the ring force with
    the paper's damping, else :mod:`microimpact.solvers.normal_models` (JKR, DMT, and Hertz with a
    DEM damping law), after checking the Tabor regime of an adhesive law
    (:func:`microimpact.model.adhesion_models.check_adhesion_regime`, an AdhesionRegimeWarning)."""
    if contact.normal_model == "ring" and contact.damping_model == "paper":
        return engine
    from microimpact.solvers import normal_models

    if contact.adhesion_line_force > 0.0:
        check_adhesion_regime(contact, stacklevel=4)
    return normal_models


def settled_contact_energy(contact) -> float:
    """Contact energy of a sphere at rest at its equilibrium: V(X) = -(4/15) m (X/T)^2 for the
    paper's law, :func:`microimpact.solvers.normal_models.settled_contact_energy` for JKR, DMT. [J]

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> e = settled_contact_energy(c)
    >>> round(e / (-4.0 / 15.0 * c.mass * (c.length_scale / c.time_scale) ** 2), 12)
    1.0
    """
    if contact.normal_model != "ring":
        from microimpact.solvers.normal_models import settled_contact_energy as settled

        return settled(contact)
    return float(contact_potential_energy(contact, contact.length_scale))


def _normal_dissipation(contact, normal_speed, captured, tracked):
    """Energy dissipated by the normal damping [J]: as tracked by the solver for a rebound; for a
    captured sphere all of it down to rest at the equilibrium, m v_n^2/2 - V(X), which does not
    depend on how far the solver followed the captured oscillation."""
    # without adhesion (a Hertz sphere that crept to rest under a DEM damping) the rest energy is 0
    settled = settled_contact_energy(contact) if contact.adhesion_line_force > 0 else 0.0
    to_rest = 0.5 * contact.mass * np.square(normal_speed) - settled
    return np.where(captured, to_rest, tracked)


def _as_dataarray(name, value, dims=None):
    import xarray as xr  # on first batch use: 0.2 s of start-up that a single impact never needs

    if isinstance(value, xr.DataArray):
        return value.rename(name)
    a = np.asarray(value, dtype=float)
    if a.ndim == 0:
        return xr.DataArray(a, name=name)
    return xr.DataArray(a, dims=dims[-a.ndim:], name=name)


def _plain_axis_names(plain: dict) -> tuple:
    """Names of the axes of numpy-broadcast plain inputs: an axis along which exactly one input
    varies (and that input along no other axis) is named after that input (``speed``,
    ``incidence_deg``); the others ``impact_<k>`` (``impact`` for a single axis)."""
    ndim = max((np.ndim(v) for v in plain.values()), default=0)
    names = []
    for k in range(ndim):
        varying = [n for n, v in plain.items()
                   if np.ndim(v) > ndim - 1 - k and np.shape(v)[k - ndim] > 1
                   and sum(size > 1 for size in np.shape(v)) == 1
                   and np.unique(np.asarray(v)).size == np.shape(v)[k - ndim]]  # distinct: an index
        others = [n for n, v in plain.items() if np.ndim(v) > ndim - 1 - k and np.shape(v)[k - ndim] > 1]
        names.append(varying[0] if len(varying) == 1 and len(others) == 1 else
                     ("impact" if ndim == 1 else f"impact_{k}"))
    if len(set(names)) < len(names):  # the same input cannot name two axes
        names = ["impact"] if ndim == 1 else [f"impact_{k}" for k in range(ndim)]
    return tuple(names)


def _index_coordinates(inputs: dict, arrays: list) -> dict:
    """An index coordinate for every dimension of the batch that has none: the values of the input
    the dimension is named after (a plain array's axis, or a DataArray on a dimension of its own
    name), else of the one DataArray input that lies along that dimension alone, else 0, 1, 2, ...
    So every dimension can be ``.sel``-ed (a DataArray without a coordinate would otherwise give a
    2-D variable named after its dimension)."""
    import xarray as xr

    dims = arrays[0].dims
    by_name = {a.name: a for a in arrays}
    coords = {}
    for d, n in zip(dims, arrays[0].shape):
        if any(d in a.coords for a in arrays):
            continue
        alone = [k for k, v in inputs.items() if isinstance(v, xr.DataArray) and v.dims == (d,)]
        name = d if d in inputs else (alone[0] if len(alone) == 1 else None)
        if name is not None:
            values = by_name[name].values[tuple(slice(None) if dd == d else 0 for dd in dims)]
            if np.unique(values).size == n:  # an index needs distinct values
                coords[d] = xr.Variable(d, values, dict(attributes(name)))
                continue
        coords[d] = xr.Variable(d, np.arange(n), {"long_name": f"index along {d}"})
    return coords


def _simulate_over_contacts(contact, contact_fields: dict, **kwargs) -> xr.Dataset:
    """simulate_many once per combination of the varied contact fields, stacked along their
    dimensions (an index coordinate of the field's values each); the ``contact_<field>``
    attribute of a varied field holds its values."""
    import xarray as xr

    known = {f.name for f in dataclasses.fields(Contact)}
    axes = []
    for name, value in contact_fields.items():
        if name not in known:
            raise TypeError(f"simulate_many got an unexpected keyword argument {name!r} (not a Contact field)")
        if isinstance(value, xr.DataArray):
            if value.ndim != 1:
                raise ValueError(f"{name}: a contact field varies along one dimension, got dims {value.dims}")
            dim, values = value.dims[0], value.values
        else:
            dim, values = name, np.atleast_1d(np.asarray(value, dtype=float))
            if values.ndim != 1:
                raise ValueError(f"{name}: a contact field varies along one dimension, got shape {values.shape}")
        axes.append((name, dim, values))
    dims = [d for _, d, _ in axes]
    if len(set(dims)) < len(dims):
        raise ValueError(f"each varied contact field needs its own dimension, got {dims}")

    def nested(level: int, chosen: dict):
        if level == len(axes):
            return simulate_many(contact.with_(**chosen), **kwargs)
        name, _, values = axes[level]
        return [nested(level + 1, chosen | {name: float(v)}) for v in values]

    ds = xr.combine_nested(nested(0, {}), concat_dim=dims, combine_attrs="override")
    ds = ds.assign_coords({d: (d, v, dict(attributes(n))) for n, d, v in axes})
    for name, dim, values in axes:
        ds.attrs[f"contact_{name}"] = np.asarray(values, dtype=float)
        ds.attrs[f"contact_{name}_dimension"] = dim
    return ds


def simulate_many(contact, speed, incidence_deg=0.0, azimuth_deg=0.0, omega=(0.0, 0.0, 0.0), friction=None, *,
                  rtol: float = DEFAULT_RTOL, method: str = "engine", family: bool | None = None,
                  **contact_fields) -> xr.Dataset:
    """Simulate a batch of impacts, broadcasting the inputs, on both cores.

    Each distinct normal speed is solved once by the compiled engine; every angle, azimuth, spin
    and friction coefficient that shares it costs only the closed-form tangential map. Captured
    impacts that need no tangential result stop at the exact energy test.

    Parameters
    ----------
    contact : Contact
    speed, incidence_deg, azimuth_deg : scalar, array_like or xarray.DataArray
        As in :func:`simulate_impact`. [m/s], [deg], [deg]
    omega : tuple of 3 scalars, arrays or DataArrays
        (omega_n, omega_t, omega_t'). [rad/s]
    friction : scalar, array_like or DataArray, optional
        Coulomb coefficient f; default ``contact.friction``. [-]
    rtol : float
        Relative tolerance of the normal solves. The default 1e-8 gives e_n and mu to ~5e-8
        (docs/benchmark.md) at half the cost of 1e-10, most of it saved on captured impacts. [-]
    method : {"engine"}
        Only the engine runs batches; for "reference" or "rkg" loop over :func:`simulate_impact`.
    family : bool or None
        How the normal solves are done. None (default) chooses: many distinct normal speeds (at
        least :data:`FAMILY_MIN_SPEEDS`) use the interpolated family of
        :func:`microimpact.solvers.family.normal_family` when it costs fewer solves than solving
        each speed, else each distinct speed is solved directly. True forces the family, False
        the direct solves. The ``normal_solve_path`` attribute of the result records which ran.
    **contact_fields
        Contact fields that vary, e.g. ``radius=xr.DataArray([1e-6, 3e-6], dims="radius")`` or
        ``radius=[1e-6, 3e-6]`` (dimension named after the field): one batch per combination,
        stacked along the fields' dimensions. The other fields stay as in ``contact`` (``f0``
        too; for f0 from a work of adhesion at each size use
        :func:`microimpact.io.material_contact`). [SI units of each field]

    Returns
    -------
    xarray.Dataset
        Dimensions from broadcasting the inputs (DataArrays by dimension name; plain arrays by
        numpy rules, each axis named after the one input that varies along it, else ``impact`` or
        ``impact_0, impact_1, ...``), then those of the varied contact fields; every dimension has
        an index coordinate (the input's values, or 0, 1, ... where no input gives distinct values). Variables are named after the fields of
        :class:`ImpactResult` (vectors split into ``_n``, ``_t``, ``_tp``) and carry ``units`` and
        ``long_name``; the inputs are included as variables. ``outcome`` is 0 for a rebound and 1
        for a capture (CF flag attributes).

    Notes
    -----
    No ``time_budget``: the work is one compiled call (the normal solves on both cores, then the
    vectorised tangential map), which cannot stop midway. A long computation made of batches
    checks its budget between them (:func:`microimpact.studies.sweeps.run_sweep` solves its speeds
    in blocks then; :class:`microimpact.solvers.Deadline`).

    References
    ----------
    Cheng, Brach & Dunn (2002)

    Dormand & Prince (1980)

    Hairer, Norsett & Wanner (1993), Secs. II.5-II.6

    Examples
    --------
    Table 1 row 2 (the paper's microsphere): captured at 0.1 and 1 m/s, a rebound at 10 m/s:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> ds = simulate_many(c, [0.1, 1.0, 10.0], 0.0)
    >>> ds["e_n"].values.round(6).tolist()
    [0.0, 0.0, 0.715808]
    """
    if contact_fields:
        return _simulate_over_contacts(contact, contact_fields, speed=speed, incidence_deg=incidence_deg,
                                       azimuth_deg=azimuth_deg, omega=omega, friction=friction, rtol=rtol,
                                       method=method, family=family)
    if method != "engine":
        raise ValueError(f"simulate_many runs method='engine' only, got {method!r}; for 'reference' or 'rkg' "
                         "call simulate_impact in a loop")
    rtol = _check_call(contact, rtol)
    check_sub_models(contact, "engine")
    omega = _check_omega(omega)
    inputs = {"speed": speed, "incidence_deg": incidence_deg, "azimuth_deg": azimuth_deg, "omega_n": omega[0],
              "omega_t": omega[1], "omega_tp": omega[2], "friction": contact.friction if friction is None else friction}
    arrays, flat = _broadcast_inputs(inputs)
    _check_scales(contact, flat["speed"], flat["incidence_deg"], (flat["omega_n"], flat["omega_t"], flat["omega_tp"]))
    if family is not None and not isinstance(family, (bool, np.bool_)):
        raise TypeError(f"family must be True, False or None, got {type(family).__name__} {family!r}")
    if _needs_coupled(contact):  # one coupled solve per impact
        results, error, n_solves, path = _coupled_batch(contact, flat, rtol)
    else:  # the closed-form tangential map settles every impact the normal solve does
        results, n_solves, path = _solve_batch(contact, flat, rtol, family)
        results["not_determined"], error = np.zeros(flat["speed"].size, dtype=np.int8), np.zeros(0)
    ds = _batch_dataset(arrays, results)
    _add_batch_attributes(ds, contact, rtol, error, n_solves, path)
    return ds


def _coupled_batch(contact, flat: dict, rtol: float):
    """(results, error, n_solves, path) of :func:`simulate_many` for a contact whose tangential
    motion acts back on the normal one: one coupled solve per impact of the flat inputs ``flat``;
    ``error`` holds the tangential error estimates [m/s] of the impacts not determined."""
    alpha, theta = np.radians(flat["incidence_deg"]), np.radians(flat["azimuth_deg"])
    v = flat["speed"]
    v_in = (-v * np.cos(alpha), v * np.sin(alpha) * np.cos(theta), v * np.sin(alpha) * np.sin(theta))
    results = _coupled_results(contact, v_in, (flat["omega_n"], flat["omega_t"], flat["omega_tp"]),
                               flat["friction"], rtol)
    error = results["tangential_error"][results["not_determined"]]
    results = {k: results[k] for k in RESULT_VARIABLES} | {"not_determined": results["not_determined"].astype(np.int8)}
    return results, error, int(v.size), "coupled: one normal-tangential solve per impact"


def _add_batch_attributes(ds: xr.Dataset, contact, rtol: float, error, n_solves: int, path: str) -> None:
    """Record on ``ds`` the impacts not determined (``error``: their error estimates [m/s]), the
    contact, the solver and its tolerance, the normal law and how the normal solves ran."""
    if error.size:  # which impacts: the not_determined flag; how far off: the largest estimate
        ds.attrs["not_determined"] = (f"{error.size} impacts: final tangential velocity and spin not settled "
                                      f"(largest error estimate {float(error.max()):.3g} m/s); see not_determined")
    ds.attrs.update(contact_attributes(contact))
    ds.attrs["solver"] = f"microimpact engine (Dormand-Prince 5(4), rtol={rtol:g})"
    if contact.normal_model != "ring":
        ds.attrs["normal_model"] = contact.normal_model
        ds.attrs["tabor_parameter"] = float(tabor_parameter(contact.radius, contact.stiffness, contact.work_of_adhesion))
    ds.attrs["normal_solves"] = n_solves
    ds.attrs["normal_solve_path"] = path


def _broadcast_inputs(inputs: dict):
    """Broadcast the inputs (plain arrays by numpy rules, then DataArrays by dimension name) and
    check them; returns the broadcast DataArrays and their flattened values."""
    import xarray as xr  # on first batch use: 0.2 s of start-up that a single impact never needs

    plain = {k: _real_array(k, v) for k, v in inputs.items() if not isinstance(v, xr.DataArray)}
    for k, v in inputs.items():
        if isinstance(v, xr.DataArray):
            _real_array(k, v)
    try:
        axes = _plain_axis_names(plain)
        if plain:
            plain = dict(zip(plain, np.broadcast_arrays(*plain.values())))
        arrays = xr.broadcast(*(_as_dataarray(k, plain.get(k, v), axes) for k, v in inputs.items()))
    except ValueError as exc:
        shapes = ", ".join(f"{k} {np.shape(v)}" for k, v in inputs.items() if np.ndim(v))
        raise ValueError(f"the inputs do not broadcast together ({shapes}): {exc}") from None
    dims = arrays[0].dims
    arrays = [a.transpose(*dims) for a in arrays]
    arrays[0] = arrays[0].assign_coords(_index_coordinates(inputs, arrays))
    flat = {a.name: np.ascontiguousarray(a.values, dtype=float).ravel() for a in arrays}
    _check_inputs(flat["speed"], flat["incidence_deg"], flat["azimuth_deg"], (flat["omega_n"], flat["omega_t"], flat["omega_tp"]))
    if np.any(~np.isfinite(flat["friction"]) | (flat["friction"] < 0.0)):
        raise ValueError("friction must be finite and >= 0")
    return arrays, flat


def _family_of(contact, speed, incidence_deg, rtol, family):
    """The interpolated family for the normal speeds of these impacts [m/s, deg], or None for
    direct solves: ``family`` False; or None with fewer than FAMILY_MIN_SPEEDS impacts, mostly
    repeated speeds (a grid), or a family that would cost more than half as many solves as there
    are impacts."""
    n = speed.size
    if family is False or n == 0:
        return None
    if contact.normal_model != "ring" or contact.damping_model != "paper":  # the family interpolates the paper's engine
        if family:
            raise ValueError("family=True covers normal_model='ring' with damping_model='paper' only, got "
                             f"normal_model={contact.normal_model!r}, damping_model={contact.damping_model!r}")
        return None
    if family is None:
        if n < FAMILY_MIN_SPEEDS:
            return None
        step = max(1, n // 4096)
        sample = speed[::step] * np.cos(np.radians(incidence_deg[::step]))
        if np.unique(sample).size < 0.5 * sample.size:
            return None
    lo, hi = normal_speed_range(speed, incidence_deg)
    try:
        return normal_family(contact, lo, hi, rtol=rtol,
                             max_solves=None if family else n // 2, n_impacts=n)
    except FamilyBudgetExceeded:
        return None


def _solve_batch(contact, flat: dict, rtol: float, family=None):
    """Normal solves and the tangential map of a flat batch; returns ({variable: 1-D array},
    number of normal solves, normal-solve path)."""
    fam = _family_of(contact, flat["speed"], flat["incidence_deg"], rtol, family)
    if fam is None:
        return (*_direct_batch(contact, flat, rtol), "direct: one engine solve per distinct normal speed")
    impacts = fam.impacts(*(flat[k] for k in ("speed", "incidence_deg", "azimuth_deg", "omega_n",
                                              "omega_t", "omega_tp", "friction")))
    results, in_band = dict(impacts.columns), impacts.in_band
    n_solves = fam.n_solves
    if np.any(in_band):  # impacts in a guard band at the capture speed: solved directly, at the
        # tolerance of the nodes beside it (e_n ~ (v_n - v_c)^(1/2) turns a solve's error near v_c
        # into a much larger e_n error: 5e-7 at rtol 1e-9 within 1 % of v_c)
        idx = np.flatnonzero(in_band)
        direct, n = _direct_batch(contact, {k: v[idx] for k, v in flat.items()}, min(rtol, NODE_RTOL_FLOOR))
        n_solves += n
        for k in results:
            results[k][idx] = direct[k]
    results["outcome"] = results["outcome"].astype(np.int8)
    results["slip_ended"] = results["slip_ended"].astype(np.int8)
    return results, n_solves, fam.describe()


def _direct_batch(contact, flat: dict, rtol: float):
    """One engine normal solve per distinct normal speed, then the tangential map; returns
    ({variable: 1-D array}, number of normal solves)."""
    alpha = np.radians(flat["incidence_deg"])
    theta = np.radians(flat["azimuth_deg"])
    v = flat["speed"]
    v_n = -v * np.cos(alpha)
    v_t = v * np.sin(alpha) * np.cos(theta)
    v_tp = v * np.sin(alpha) * np.sin(theta)
    w = (flat["omega_n"], flat["omega_t"], flat["omega_tp"])
    f = flat["friction"]
    m, inertia, r = contact.mass, contact.moment_of_inertia, contact.radius
    u_t, u_tp = slip_velocity(r, v_t, v_tp, w[1], w[2])
    needs_tangential = (f > 0.0) & ((np.hypot(u_t, u_tp) > 0.0) | (w[0] != 0.0))

    speeds, inverse = np.unique(-v_n, return_inverse=True)
    need_tail = np.bincount(inverse, weights=needs_tangential, minlength=speeds.size) > 0
    # a captured sphere is followed until every impact sharing its normal speed has stopped
    # sliding and twisting
    j_stop = np.zeros(speeds.size)
    ja_stop = np.zeros(speeds.size)
    j_star, ja_star = stop_impulses(m, inertia, f, np.hypot(u_t, u_tp), w[0])
    np.maximum.at(j_stop, inverse, np.where(needs_tangential, j_star, 0.0))
    np.maximum.at(ja_stop, inverse, np.where(needs_tangential, ja_star, 0.0))
    sol = _normal_solver(contact).solve_normal_many(contact, speeds, need_tail, rtol=rtol,
                                                    friction_impulse_stop=j_stop, twist_impulse_stop=ja_stop)
    g = {k: val[inverse] for k, val in sol.items()}
    captured = g["captured"]

    tan = tangential_outcome(m, inertia, r, f, (v_n, v_t, v_tp), w, g["friction_impulse"], g["twist_impulse"])
    vn_out = np.where(captured, 0.0, -g["e_n"] * v_n)
    coef = impact_coefficients(m, inertia, (v_n, v_t, v_tp), w, (vn_out, tan["v_t"], tan["v_tp"]),
                               (tan["omega_n"], tan["omega_t"], tan["omega_tp"]), captured)
    results = {
        "outcome": captured.astype(np.int8),
        "e_n": g["e_n"],
        **{k: coef[k] for k in ("mu_t", "mu_tp", "K_L", "K_t")},
        "velocity_out_n": vn_out,
        "velocity_out_t": tan["v_t"],
        "velocity_out_tp": tan["v_tp"],
        "omega_out_n": tan["omega_n"],
        "omega_out_t": tan["omega_t"],
        "omega_out_tp": tan["omega_tp"],
        "contact_time": g["contact_time"],
        "max_penetration": g["max_penetration"],
        "slip_ended": tan["slip_ended"].astype(np.int8),
        "friction_impulse": g["friction_impulse"],
        "dissipated_energy": _normal_dissipation(contact, -v_n, captured, g["dissipated_energy"])
        + tan["friction_dissipation"],
    }
    return results, int(speeds.size)


def _batch_dataset(arrays, results: dict) -> xr.Dataset:
    """The inputs and results of a batch as a Dataset with the inputs' dimensions and coordinates;
    every variable carries the ``units`` and ``long_name`` of :mod:`microimpact.io.variables`."""
    import xarray as xr  # on first batch use: 0.2 s of start-up that a single impact never needs

    dims, shape = arrays[0].dims, arrays[0].shape
    coords = {name: c for a in arrays for name, c in a.coords.items()}
    # built in one call: adding the variables one by one costs a merge of xarray's each
    data = {a.name: (dims, a.values, dict(attributes(a.name))) for a in arrays if a.name not in coords}
    data.update({name: (dims, values.reshape(shape), dict(attributes(name))) for name, values in results.items()})
    ds = xr.Dataset(data, coords=coords)
    ds["outcome"].attrs.update(flag_values=np.array([0, 1], dtype=np.int8), flag_meanings="rebound capture")
    ds["slip_ended"].attrs.update(flag_values=np.array([0, 1], dtype=np.int8), flag_meanings="sliding rolling")
    ds["not_determined"].attrs.update(flag_values=np.array([0, 1], dtype=np.int8), flag_meanings="determined not_determined")
    return ds
