"""An independent scipy integration of the hysteretic tangential law on an elastic Hertz contact.

The compiled coupled solver (:mod:`microimpact.solvers.coupled`) integrates the
Mindlin-Deresiewicz law of :mod:`microimpact.model.tangential_compliance` in nondimensional form,
with its own step control, event location and captured-tail logic. This module integrates the same
law in SI units with :func:`scipy.integrate.solve_ivp` (DOP853) and shares none of that: the state is
(x, x', v_t, omega_t', p, c, int F_n dt, int T u dt), turning points (the slip along the branch,
s u, changes sign) are terminal events after which the branch restarts at p = 0, and the force law
and branch rate are the model's functions. It serves two purposes:

* a yardstick for the coupled solver on the contacts it covers (elastic Hertz normal law, no
  adhesion, no damping, the net Coulomb limit f F_n, no rolling resistance, no initial spin, a
  tangential impact in one plane), tested in tests/test_contact_models.py;
* the readings of a turning point held by a falling load (``unloading``, the keys of
  :data:`~microimpact.model.tangential_compliance.MD_UNLOADING_EXPONENTS`), which the Kharaz
  comparison (:mod:`microimpact.analysis.kharaz`) shows beside the solvers' "limit" reading. The
  compiled solvers implement "limit" only.

The integration starts at x0 = 1e-12 of the largest penetration, in gross slip (p = 1, c = 1), with
the normal speed there from energy conservation. A contact that does not slide leaves gross slip
within the first steps (the branch rate grows like 1/x there) for its self-similar state, which
the compiled solver starts on; the start in gross slip costs an error of order x0 / x_max in the
rebound (measured: 4e-6 of v_t,in at 1e-6, 4e-8 at 1e-8, 7e-12 at 1e-12; 0.5 deg incidence).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from microimpact.model import tangential_compliance as tc
from microimpact.model.coefficients import impact_coefficients
from microimpact.model.contact import Contact
from microimpact.model.kinematics import ImpactResult

__all__ = ["hysteretic_reference"]

_X, _XD, _VT, _WTP, _P, _C, _J, _W = range(8)
_START = 1e-12  # x0 / x_max


def _check_covered(contact: Contact) -> None:
    """Raise ValueError naming the first field outside what this integration covers."""
    need = {"tangential_model": "mindlin_deresiewicz", "friction_model": "net", "normal_model": "ring",
            "damping_model": "paper"}
    for name, value in need.items():
        if getattr(contact, name) != value:
            raise ValueError(f"hysteretic_reference covers {name}={value!r} only, got {getattr(contact, name)!r}")
    for name in ("adhesion_line_force", "zeta_hertz", "zeta_adhesion", "rolling_friction"):
        if getattr(contact, name) != 0.0:
            raise ValueError(f"hysteretic_reference covers {name}=0 only (elastic Hertz contact, no rolling "
                             f"resistance), got {getattr(contact, name)!r}")


def _integrate(contact: Contact, vn: float, vt: float, exponent: float, rtol: float):
    """Integrate from x0 to separation: (final state, separation time [s], first turning point's
    time [s] or NaN, largest penetration [m])."""
    speed = math.hypot(vn, vt)
    m, r, inertia, f = contact.mass, contact.radius, contact.moment_of_inertia, contact.friction
    k_h = math.sqrt(r) * contact.stiffness  # F_n = k_h x^(3/2)
    x_max = (1.25 * m * vn * vn / k_h) ** 0.4
    branch = {"s": 1.0}

    def forces(z):
        x = max(z[_X], 0.0)
        fn = k_h * x**1.5
        lim = f * fn
        lim_rate = f * 1.5 * k_h * math.sqrt(x) * z[_XD]
        kt = float(tc.tangential_stiffness(contact.shear_modulus, math.sqrt(r * x)))
        u = z[_VT] + r * z[_WTP]
        t = lim * tc.md_force_ratio(z[_P], branch["s"], z[_C])
        return fn, lim, lim_rate, kt, u, t

    def rhs(_t, z):
        fn, lim, lim_rate, kt, u, t = forces(z)
        dp = tc.md_branch_rate(z[_P], z[_C], branch["s"] * u, kt, lim, lim_rate) if lim > 0.0 else 0.0
        dc = 0.0
        if z[_P] <= 0.0 and dp == 0.0 and lim_rate < 0.0:  # held at its turning point by the falling load
            dc = tc.md_held_span_rate(z[_C], lim, lim_rate, exponent)
        return [z[_XD], -fn / m, -t / m, -r * t / inertia, dp, dc, fn, t * u]

    def separation(_t, z):
        return z[_X]

    def turning(_t, z):
        return branch["s"] * (z[_VT] + r * z[_WTP])

    def deepest(_t, z):
        return z[_XD]

    separation.terminal, separation.direction = True, -1
    turning.terminal, turning.direction = True, -1
    deepest.direction = -1
    x0 = _START * x_max
    z = np.array([x0, math.sqrt(vn * vn - 0.8 * k_h * x0**2.5 / m), vt, 0.0, 1.0, 1.0, 0.0, 0.0])
    scale = np.array([x_max, speed, speed, speed / r, 1.0, 1.0, m * speed, m * speed * speed])
    t0, t_end = x0 / vn, 20.0 * x_max / vn  # contact time of an elastic Hertz impact: 2.94 x_max / v_n
    first_turn, x_deep = math.nan, 0.0
    for _ in range(100000):
        sol = solve_ivp(rhs, (t0, t_end), z, method="DOP853", rtol=rtol, atol=rtol * 1e-3 * scale,
                        events=(separation, turning, deepest))
        if sol.status < 0:  # pragma: no cover - solve_ivp failed
            raise RuntimeError(f"hysteretic_reference: solve_ivp failed: {sol.message}")
        z, t0 = sol.y[:, -1].copy(), float(sol.t[-1])
        if sol.t_events[2].size:
            x_deep = max(x_deep, float(sol.y_events[2][-1][_X]))
        if sol.t_events[0].size:
            break
        if not sol.t_events[1].size:  # pragma: no cover - t_end is 7x the contact time
            raise RuntimeError("hysteretic_reference: no separation within 20 x_max / v_n")
        ratio = tc.md_force_ratio(z[_P], branch["s"], z[_C])
        branch["s"] = -branch["s"]
        z[_C], z[_P] = min(tc.md_turning_span(ratio, branch["s"]), 2.0), 0.0
        first_turn = t0 if math.isnan(first_turn) else first_turn
    else:  # pragma: no cover - turning points accumulate
        raise RuntimeError("hysteretic_reference: more than 100000 turning points")
    return z, t0, first_turn, x_deep


def hysteretic_reference(contact: Contact, speed: float, incidence_deg: float, *, unloading: str = "limit",
                         rtol: float = 1e-10) -> ImpactResult:
    """One oblique impact of a non-spinning sphere with the hysteretic tangential law (scipy DOP853).

    Parameters
    ----------
    contact : Contact
        ``tangential_model="mindlin_deresiewicz"``, ``friction_model="net"``, the ring normal model
        with no adhesion and no damping (an elastic Hertz contact), no rolling resistance; other
        contacts raise ValueError naming the field.
    speed : float
        Impact speed. [m/s]
    incidence_deg : float
        Angle from the surface normal, in [0, 90). [deg]
    unloading : str
        The reading of a turning point held by a falling load, a key of
        :data:`~microimpact.model.tangential_compliance.MD_UNLOADING_EXPONENTS`: "limit" (the
        solvers' law), "rescaled_displacement", "displacement" or "force".
    rtol : float
        Relative tolerance of solve_ivp (absolute tolerances scaled by the largest penetration,
        the speed and the rim speed).

    Returns
    -------
    ImpactResult
        ``method`` is "reference:hysteretic (DOP853, unloading=<reading>)"; ``dissipated_energy``
        is the friction work int T u dt integrated as a state (the tangential energy still stored
        at separation is zero, since the limit vanishes there), so that the kinetic energy balance
        is an independent check; ``slip_ended`` means a turning point occurred.

    References
    ----------
    Mindlin, R. D. and Deresiewicz, H. (1953), J. Appl. Mech. 20:327-344; Thornton, C. (1991),
    J. Phys. D 24:1942-1946 (the law, :mod:`microimpact.model.tangential_compliance`).

    Examples
    --------
    A 5 mm alumina sphere on glass at 3.9 m/s and 45 deg slides throughout, so the tangential
    restitution is the rigid sliding value 1 - f (1 + e_n) / tan(alpha) with e_n = 1:

    >>> from microimpact.io.materials import default_materials_path, read_materials
    >>> pair = read_materials(default_materials_path())["alumina_on_soda_lime_glass"]
    >>> c = pair.contact(2.5e-3).with_(tangential_model="mindlin_deresiewicz", zeta_hertz=0.0,
    ...                                zeta_adhesion=0.0)
    >>> r = hysteretic_reference(c, 3.9, 45.0)
    >>> v_t = 3.9 * math.sin(math.radians(45.0))
    >>> round(r.e_n, 9), abs(r.velocity_out[1] / v_t - (1 - 2 * c.friction)) < 1e-9
    (1.0, True)

    The kinetic energy lost equals the integrated friction work. The loss is 1/6900 of the kinetic
    energy, so the normal solve's error at rtol 1e-10 (e_n off 1 by about 4e-11) appears in it
    magnified to about 1e-6; the balance is therefore checked to 1e-5, not to the last digits:

    >>> ke = lambda v, w: 0.5 * c.mass * sum(x * x for x in v) + 0.5 * c.moment_of_inertia * sum(x * x for x in w)
    >>> r2 = hysteretic_reference(c, 3.9, 2.0, unloading="force")
    >>> loss = ke(r2.velocity_in, r2.omega_in) - ke(r2.velocity_out, r2.omega_out)
    >>> abs(loss / r2.dissipated_energy - 1.0) < 1e-5, r2.slip_ended
    (True, True)
    """
    if unloading not in tc.MD_UNLOADING_EXPONENTS:
        raise ValueError(f"unloading must be one of {', '.join(tc.MD_UNLOADING_EXPONENTS)}, got {unloading!r}")
    _check_covered(contact)
    speed, incidence_deg = float(speed), float(incidence_deg)
    if not (math.isfinite(speed) and speed > 0.0):
        raise ValueError(f"speed must be finite and > 0, got {speed!r}")
    if not 0.0 <= incidence_deg < 90.0:
        raise ValueError(f"incidence_deg must lie in [0, 90), got {incidence_deg!r}")
    alpha = math.radians(incidence_deg)
    vn, vt = speed * math.cos(alpha), speed * math.sin(alpha)
    z, t_sep, first_turn, x_deep = _integrate(contact, vn, vt, tc.MD_UNLOADING_EXPONENTS[unloading], rtol)
    m, inertia = contact.mass, contact.moment_of_inertia
    vel_in, omega_in = (-vn, vt, 0.0), (0.0, 0.0, 0.0)
    vel_out, omega_out = (-float(z[_XD]), float(z[_VT]), 0.0), (0.0, 0.0, float(z[_WTP]))
    co = impact_coefficients(m, inertia, vel_in, omega_in, vel_out, omega_out, False)
    return ImpactResult(
        outcome="rebound", **{k: float(co[k]) for k in ("e_n", "mu_t", "mu_tp", "K_L", "K_t")},
        velocity_in=vel_in, omega_in=omega_in, velocity_out=vel_out, omega_out=omega_out,
        contact_time=t_sep, capture_time=math.nan, max_penetration=x_deep,
        slip_ended=not math.isnan(first_turn), slip_end_time=first_turn,
        friction_impulse=float(z[_J]), dissipated_energy=float(z[_W]), final_contact_energy=0.0,
        method=f"reference:hysteretic (DOP853, unloading={unloading})", stop_reason="separation")
