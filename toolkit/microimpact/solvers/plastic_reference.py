"""An independent scipy integration of a normal impact under the Thornton & Ning (1998) law.

The law (:mod:`microimpact.model.thornton_ning`) states its forces and its state; this module
integrates m delta'' = -F with :func:`scipy.integrate.solve_ivp` (DOP853) and shares nothing with
the compiled solvers (a yardstick does not share the code it checks), nor with the law's energy
account (:func:`~microimpact.model.thornton_ning.impact_energies`), which it is tested against.
It is the pattern a plastic law needs from any driver:

1. loading, from first contact (delta = 0, delta' = V_i) on the loading curve (TN1)-(TN3), to the
   turning point delta' = 0 (event) -> delta_max;
2. the law's state update at the turning point: :func:`~microimpact.model.thornton_ning.unloading_state`
   (R_p, delta_p, the break);
3. unloading (and elastic reloading) on (TN6), to the break delta = delta_break with delta' < 0
   (event: the sphere separates with e = |delta'| / V_i), or to a turning point delta' = 0 with
   delta' rising (event: captured, e = 0; undamped, it then oscillates on (TN6) forever and never
   again reaches delta_max, so no further plastic state update is needed).

The law's yield (TN2) is the model's :func:`~microimpact.model.thornton_ning.yield_point` (where
the JKR force per contact area reaches p_y, not the paper's centre pressure; the model module says
why), read through the law's forces, the one place it is written.

Variables are nondimensional: delta / L and t / (L / V_i), L the undamped Hertz largest approach at
V_i, (5 m V_i^2 / (4 K sqrt(R)))^(2/5). A third state variable integrates the work of the contact
force, so that the energy account is checked along the integration too.

References
----------
Thornton, C. and Ning, Z. (1998), A theoretical model for the stick/bounce behaviour of adhesive,
elastic-plastic spheres, Powder Technol. 99:154-162, doi:10.1016/S0032-5910(98)00099-0.
Hairer, E., Norsett, S. P. and Wanner, G. (1993), Solving Ordinary Differential Equations I, 2nd
ed., Springer (DOP853).
"""

from __future__ import annotations

import math
from dataclasses import asdict

import numpy as np
from scipy.integrate import solve_ivp

from microimpact.model import thornton_ning as tn
from microimpact.solvers.solution import NormalSolution

__all__ = ["plastic_impact", "REFERENCE_RTOL"]

#: relative tolerance of the DOP853 integration; the absolute one is REFERENCE_RTOL * 1e-3 of the
#: nondimensional state (its scale is 1). Chosen so that e agrees with the closed forms to 1e-8.
REFERENCE_RTOL = 1e-12


def _solve(rhs, y0, events, span):
    """solve_ivp with DOP853 and the module's tolerances; RuntimeError naming the failure."""
    sol = solve_ivp(rhs, (0.0, span), y0, method="DOP853", events=events, rtol=REFERENCE_RTOL,
                    atol=REFERENCE_RTOL * 1e-3, dense_output=False)
    if sol.status < 0:
        raise RuntimeError(f"plastic_impact: solve_ivp failed: {sol.message}")
    return sol


def _first_event(sol):
    """(index of the event that stopped sol, its state, its time) or (None, last state, last time)."""
    for i, ys in enumerate(sol.y_events):
        if len(ys):
            return i, ys[0], sol.t_events[i][0]
    return None, sol.y[:, -1], sol.t[-1]


def plastic_impact(pc: tn.PlasticContact, normal_speed: float) -> NormalSolution:
    """Integrate one undamped normal impact at ``normal_speed`` under the Thornton & Ning law.

    Parameters
    ----------
    pc : PlasticContact
        The contact (R, m, K, w, p_y).
    normal_speed : float
        Incident normal speed V_i > 0. [m/s]

    Returns
    -------
    NormalSolution
        As :func:`microimpact.solvers.thornton_ning_law.solve_thornton_ning`'s (the same fields
        and the same ``state``, here also ``work_loading``, the work of the contact force on the
        loading curve, and ``work_unloading``, the work it returns from delta_max to the end [J]);
        ``n_steps`` counts solve_ivp's points.

    Raises
    ------
    ValueError
        If ``normal_speed`` is not a finite number > 0.
    RuntimeError
        If the integration fails or ends at neither event.

    References
    ----------
    Thornton & Ning (1998), Powder Technol. 99:154-162.

    Examples
    --------
    Without adhesion, Thornton's (1997) closed form at V_i = 4 V_y:

    >>> pc = tn.PlasticContact(1e-6, 1e-14, 4e9 / 3, 0.0, 1e8)
    >>> r = plastic_impact(pc, 4 * tn.yield_velocity(pc))
    >>> r.stop_reason, round(r.e_n, 8), round(float(tn.thornton_restitution(0.25)), 8)
    ('separation', 0.81227887, 0.81227887)
    """
    v_i = float(normal_speed)
    if not (math.isfinite(v_i) and v_i > 0.0):
        raise ValueError(f"plastic_impact: normal_speed must be a finite number > 0, got {normal_speed!r}")
    length = (1.25 * pc.mass * v_i * v_i / (pc.stiffness * math.sqrt(pc.radius))) ** 0.4
    acc = length / (pc.mass * v_i * v_i)  # (force [N]) * acc = nondimensional acceleration
    work_unit = pc.mass * v_i * v_i  # y[2] * work_unit = int F d delta [J]

    def loading(_t, y):
        f = float(tn.loading_force(pc, y[0] * length))
        return [y[1], -f * acc, f * acc * y[1]]

    def turned(_t, y):
        return y[1]

    turned.terminal, turned.direction = True, -1.0
    first = _solve(loading, [0.0, 1.0, 0.0], [turned], 50.0)
    i, y_max, t_max = _first_event(first)
    if i is None:
        raise RuntimeError("plastic_impact: the loading did not reach a turning point")
    state = tn.unloading_state(pc, y_max[0] * length)
    d_break = state.break_approach / length

    def unloading(_t, y):
        f = float(tn.unloading_force(pc, state, y[0] * length))
        return [y[1], -f * acc, -f * acc * y[1]]

    def broke(_t, y):
        return y[0] - d_break

    def stuck(_t, y):
        return y[1]

    broke.terminal, broke.direction = True, -1.0
    stuck.terminal, stuck.direction = True, 1.0
    # the turning point itself has y[1] = 0: start just after it on the unloading curve (one Taylor step)
    h = 1e-9
    f0 = float(tn.unloading_force(pc, state, state.max_approach)) * acc
    y0 = [y_max[0] - 0.5 * f0 * h * h, -f0 * h, 0.5 * f0 * f0 * h * h]
    sol = _solve(unloading, y0, [broke, stuck], 1e3)
    j, y_end, t_end = _first_event(sol)
    if j is None:
        raise RuntimeError("plastic_impact: the unloading reached neither the break nor a turning point")
    captured = j == 1
    rebound = 0.0 if captured else float(abs(y_end[1])) * v_i
    loaded, returned = float(y_max[2]) * work_unit, float(y_end[2]) * work_unit
    end = float(t_max + t_end + h) * length / v_i
    return NormalSolution(
        outcome="capture" if captured else "rebound", e_n=rebound / v_i,
        contact_time=math.inf if captured else end, capture_time=end if captured else math.nan,
        max_penetration=state.max_approach, friction_impulse=math.nan, twist_impulse=math.nan,
        dissipated_energy=math.nan if captured else loaded - returned, final_energy=0.5 * pc.mass * rebound**2,
        slip_end_time=math.nan, n_steps=int(first.t.size + sol.t.size), n_rejected=0,
        stop_reason="capture" if captured else "separation",
        state={**asdict(state), "work": loaded - returned, "work_loading": loaded, "work_unloading": returned})
