"""Impact kinematics and the result record (the coefficients of Eqs. (21)-(25) are in
:mod:`microimpact.model.coefficients`, compiled, so that importing this module loads no numba).

Frame and signs (the paper's Fig. 6 is missing from the text; this is the convention of the toolkit):

* (n, t, t'): n is the outward surface normal, t and t' span the surface.
* Incident velocity of magnitude v at incidence angle alpha from the normal and azimuth theta in
  the tangent plane: v_n = -v cos(alpha), v_t = v sin(alpha) cos(theta), v_t' = v sin(alpha) sin(theta).
* Spin omega = (omega_n, omega_t, omega_t'). Eqs. (19)-(20) are used as printed,
  I omega_t' ' = r F_t and I omega_t ' = -r F_t', so the slip velocity of the contact point that
  friction opposes is u_t = v_t + r omega_t', u_t' = v_t' - r omega_t. Rolling without slip in +t
  therefore has omega_t' = -v_t / r.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

__all__ = [
    "ImpactResult",
    "flat_broadcast",
    "incident_velocity",
    "slip_velocity",
]

def incident_velocity(speed: float, incidence_deg: float, azimuth_deg: float) -> tuple[float, float, float]:
    """Incident velocity components (v_n, v_t, v_t') from magnitude and angles. [m/s]

    Parameters
    ----------
    speed : float
        Magnitude of the incident velocity. [m/s]
    incidence_deg : float
        Angle from the surface normal, in [0, 90). [deg]
    azimuth_deg : float
        Direction of the tangential component in the (t, t') plane, from t towards t'. [deg]
    
    References
    ----------
    Cheng, Brach & Dunn (2002), Fig. 1 (the frame n, t, t')

    Examples
    --------
    2 m/s at 60 deg from the normal, towards t' (azimuth 90 deg):

    >>> [round(v, 12) + 0.0 for v in incident_velocity(2.0, 60.0, 90.0)]
    [-1.0, 0.0, 1.732050807569]
    """
    a = math.radians(incidence_deg)
    th = math.radians(azimuth_deg)
    return -speed * math.cos(a), speed * math.sin(a) * math.cos(th), speed * math.sin(a) * math.sin(th)


def flat_broadcast(*arrays):
    """(shape, flat arrays): ``arrays`` (numpy arrays) broadcast to one shape, each 1-D and
    contiguous, as the compiled kernels take them.

    An array that already has the shape is raveled (a view when it is contiguous); one that needs
    broadcasting is copied. numba is never handed a view made by ``np.broadcast_arrays``, whose
    writeable flag warns when read (a FutureWarning from numba's typing).

    Examples
    --------
    >>> import numpy as np
    >>> shape, (a, b) = flat_broadcast(np.ones(3), np.array(2.0))
    >>> shape, b.tolist()
    ((3,), [2.0, 2.0, 2.0])
    """
    shape = np.broadcast_shapes(*(a.shape for a in arrays))
    return shape, [np.ascontiguousarray(a).ravel() if a.shape == shape else np.array(np.broadcast_to(a, shape)).ravel()
                   for a in arrays]


def slip_velocity(radius, v_t, v_tp, omega_t, omega_tp):
    """Velocity of the contact point relative to the surface, (u_t, u_t'). [m/s]

    u_t = v_t + r omega_t', u_t' = v_t' - r omega_t (consistent with Eqs. (19)-(20) as printed).

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (19)-(20).

    Examples
    --------
    A sphere of 1 um radius moving at 1 m/s and spinning at omega_t' = -1e6 rad/s rolls: no slip.

    >>> slip_velocity(1e-6, 1.0, 0.0, 0.0, -1e6)
    (0.0, 0.0)
    """
    return v_t + radius * omega_tp, v_tp - radius * omega_t


@dataclass(frozen=True)
class ImpactResult:
    """Outcome of one impact. Vectors are (n, t, t') components.

    Attributes
    ----------
    outcome : str
        "rebound" or "capture".
    e_n : float
        Normal restitution coefficient, Eq. (21); 0 when captured. [-]
    mu_t, mu_tp : float
        Tangential impulse ratios in t and t', Eqs. (22)-(23); NaN when captured. [-]
    K_L, K_t : float
        Translational and total kinetic energy loss ratios, Eqs. (25) and (24). [-]
    velocity_in, velocity_out : tuple of float
        Centre velocity before and after (final state when captured). [m/s]
    omega_in, omega_out : tuple of float
        Spin before and after. [rad/s]
    contact_time : float
        Duration of contact; inf when captured (the sphere stays). [s]
    capture_time : float
        Time at which the contact energy first fell below zero; NaN for a rebound. [s]
    max_penetration : float
        Largest approach x = -n of the centre. [m]
    slip_ended : bool
        True if friction brought the contact-point slip to zero (the sphere then rolls).
    slip_end_time : float
        Time at which sliding ended; NaN if it did not. [s]
    friction_impulse : float
        int |F_n| dt over the contact (|F_n + 2 F_po| with ``friction_model="pulloff"``); for a
        captured sphere over the part followed, which lasts until sliding and twist have ended or
        the rest of the tail is negligible (a compliant contact with the pulloff limit and no
        rolling resistance: until capture and the largest penetration). [N s]
    dissipated_energy : float
        Energy dissipated by normal damping plus friction (sliding and twist), so that initial
        kinetic energy = final kinetic energy + final_contact_energy + dissipated_energy. For a
        rebound the damping part is integrated by the solver; for a captured sphere it is all the
        damping down to rest at the equilibrium. [J]
    final_contact_energy : float
        Normal contact energy left at the end: 0 for a rebound; for a captured sphere the energy
        V(X) = -(4/15) m (X/T)^2 of the sphere at rest at the equilibrium. [J]
    method : str
        The solver: "engine", "engine:coupled (<tangential model>, <friction model>)", "rkg" or
        "reference:<scipy method>".
    stop_reason : str
        Why the integration stopped: "separation" (rebound), "capture" (the energy test, nothing
        tangential left that the rest of the motion could change), "settled" or "slip and twist
        ended" (a captured sphere followed for its tangential outcome).
    not_determined : str
        What the solver could not determine to its tolerance, with its error estimate; empty when
        every value is determined. Set for a captured sphere held by friction with rolling
        resistance whose final tangential velocity and spin moved beyond
        :data:`~microimpact.solvers.coupled.HELD_ROLLING_TOLERANCE` between two tolerances (an
        :class:`~microimpact.solvers.UndeterminedOutcomeWarning` is issued as well).

    Examples
    --------
    An oblique rebound of the paper's microsphere: the energy balance of ``dissipated_energy``
    closes to the solver's tolerance, and ``to_dict`` is valid JSON (the NaN capture time becomes
    null):

    >>> import json
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> from microimpact.solvers.impact import simulate_impact
    >>> r = simulate_impact(c, 2.0, 30.0)
    >>> def kinetic(v, w):
    ...     squares = sum(x * x for x in v), sum(x * x for x in w)
    ...     return 0.5 * (c.mass * squares[0] + c.moment_of_inertia * squares[1])
    >>> ke_in = kinetic(r.velocity_in, r.omega_in)
    >>> ke_out = kinetic(r.velocity_out, r.omega_out)
    >>> balance = ke_in - ke_out - r.dissipated_energy - r.final_contact_energy
    >>> r.outcome, abs(balance) / ke_in < 1e-6, json.loads(json.dumps(r.to_dict()))["capture_time"]
    ('rebound', True, None)
    """

    outcome: str
    e_n: float
    mu_t: float
    mu_tp: float
    K_L: float
    K_t: float
    velocity_in: tuple[float, float, float]
    omega_in: tuple[float, float, float]
    velocity_out: tuple[float, float, float]
    omega_out: tuple[float, float, float]
    contact_time: float
    capture_time: float
    max_penetration: float
    slip_ended: bool
    slip_end_time: float
    friction_impulse: float
    dissipated_energy: float
    final_contact_energy: float
    method: str
    stop_reason: str
    not_determined: str = ""

    def to_dict(self) -> dict:
        """Plain dict; non-finite floats become None so that the result is valid JSON."""

        def clean(v):
            if isinstance(v, float) and not math.isfinite(v):
                return None
            if isinstance(v, tuple):
                return [clean(x) for x in v]
            return v

        return {k: clean(v) for k, v in asdict(self).items()}
