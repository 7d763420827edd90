"""One table of the toolkit's variable names, units and long names.

Every NetCDF variable and every Dataset variable the toolkit writes takes its ``units`` and
``long_name`` from :data:`VARIABLES`, so a name means the same quantity, in the same unit, in every
file. Units are UDUNITS spellings in one style, as CF-1.10 asks (``m s-1``, not ``m/s``; ``rad s-1``,
``J m-2``, ``degree``); ``1`` is dimensionless. :func:`udunits` turns the other spellings the toolkit
has used into this style; :func:`microimpact.io.files.write_netcdf` applies it to every ``units``.

Example
-------
>>> from microimpact.io.variables import attributes
>>> attributes("e_n")["units"]
'1'
"""

from __future__ import annotations

__all__ = ["VARIABLES", "UNIT_SPELLINGS", "attributes", "variable", "udunits"]

#: name: (units, long_name); units None for text (no ``units`` attribute)
VARIABLES: dict[str, tuple[str | None, str]] = {
    # ------------------------------------------------------------- impact inputs
    "speed": ("m s-1", "incident speed v"),
    "normal_speed": ("m s-1", "incident normal speed v_n"),
    "incidence_deg": ("degree", "incidence angle alpha from the surface normal"),
    "azimuth_deg": ("degree", "azimuth theta of the tangential velocity, from t towards t'"),
    "omega_n": ("rad s-1", "initial spin omega_n about the normal n"),
    "omega_t": ("rad s-1", "initial spin omega_t about t"),
    "omega_tp": ("rad s-1", "initial spin omega_t' about t'"),
    "friction": ("1", "Coulomb friction coefficient f"),
    "radius": ("m", "sphere radius r"),
    # ------------------------------------------------------------- impact results
    "outcome": ("1", "impact outcome (0 rebound, 1 capture)"),
    "e_n": ("1", "normal coefficient of restitution, Eq. (21)"),
    "mu_t": ("1", "tangential impulse ratio in t, Eq. (22)"),
    "mu_tp": ("1", "tangential impulse ratio in t', Eq. (23)"),
    "K_L": ("1", "translational kinetic energy loss ratio, Eq. (25)"),
    "K_t": ("1", "total kinetic energy loss ratio, Eq. (24)"),
    "velocity_out_n": ("m s-1", "normal velocity after impact (final state if captured)"),
    "velocity_out_t": ("m s-1", "tangential velocity in t after impact"),
    "velocity_out_tp": ("m s-1", "tangential velocity in t' after impact"),
    "omega_out_n": ("rad s-1", "spin about n after impact"),
    "omega_out_t": ("rad s-1", "spin about t after impact"),
    "omega_out_tp": ("rad s-1", "spin about t' after impact"),
    "contact_time": ("s", "duration of contact (inf if captured)"),
    "max_penetration": ("m", "largest penetration x = -n"),
    "slip_ended": ("1", "1 if sliding ended and the sphere rolls"),
    "friction_impulse": ("N s", "integral of |F_n| over the contact"),
    "dissipated_energy": ("J", "energy dissipated by damping and friction (to rest if captured)"),
    "not_determined": ("1", "1 if the solver cannot settle the final tangential velocity and spin to its tolerance"),
    "capture_normal_speed": ("m s-1", "normal capture velocity: largest normal speed that is captured"),
    # ------------------------------------------------------------- fitted parameters
    "zeta_hertz": ("1", "nondimensional Hertzian damping coefficient zeta_H, Eq. (15)"),
    "zeta_adhesion": ("1", "nondimensional adhesion damping coefficient zeta_A, Eq. (14)"),
    "work_of_adhesion": ("J m-2", "Dupre work of adhesion w_A, f0 from Eq. (7)"),
    # --- analysis (fit points, measurement flags, Kharaz et al. 2001 validation)
    "row": ("1", "data row of the impact in the source CSV"),
    "e_n_measured": ("1", "measured normal coefficient of restitution"),
    "e_n_model": ("1", "model normal coefficient of restitution at the best fit, Eq. (21)"),
    "sigma": ("1", "uncertainty of e_n used as weight (effective variance included)"),
    "residual": ("1", "(model - measured) / sigma"),
    "correlation": ("1", "correlation of the fitted parameters"),
    "capture_speed_ratio": ("1", "incident normal speed / capture velocity"),
    "spin_bound": ("rad s-1", "largest initial spin sampled"),
    "angle_uncertainty_deg": ("degree", "incidence-angle uncertainty used"),
    "e_n_limit": ("1", "e_n spread limit (e_n_uncertainty, else threshold_e_n)"),
    "tangential_restitution": ("1", "tangential restitution v_t,out / v_t,in of the centre of mass"),
    "rebound_spin": ("rad s-1", "angular speed |omega| after impact"),
    "rebound_angle": ("degree", "rebound angle from the surface normal"),
    # --- studies (stress sweep, work-precision benchmark)
    "density": ("kg m-3", "sphere density"),
    "stiffness": ("Pa", "effective material stiffness K, Eq. (3)"),
    "energy_error": ("1", "energy-balance residual over the energy scale of the case"),
    "convergence_error": ("1", "distance of the results at rtol 1e-8 and 1e-10 (stress.result_distance)"),
    "convergence_error_tight": ("1", "distance of the results at rtol 1e-10 and 1e-12 (run where "
                                "convergence_error exceeds its tolerance)"),
    "reference_error": ("1", "distance of the engine and 3-D reference results (stress.result_distance)"),
    "seconds": ("s", "computing time of the case"),
    "time_per_impact": ("s", "median computing time per impact"),
    "time_per_impact_normal_solve": ("s", "engine row only: median time of one engine.solve_normal call "
                                     "(the normal solve without simulate_impact's Python layer)"),
    "max_error_e_n": ("1", "max over the normal-speed set of |e_n - e_n_ref|"),
    "max_rel_error_e_n": ("1", "max over the normal-speed set of |e_n - e_n_ref| / e_n_ref"),
    "max_error_mu": ("1", "max over rebounding oblique cases of |mu_t - ref| and |mu_t' - ref|"),
    "max_error_K_L": ("1", "max over all oblique cases of |K_L - K_L_ref|"),
    "n_impacts": ("1", "distinct impacts per timing (batch size for batch methods)"),
    "rtol": ("1", "relative tolerance (adaptive methods)"),
    "steps_per_contact": ("1", "fixed steps per estimated contact duration (RKG)"),
    "mean_steps": ("1", "mean accepted steps per impact (engine, RKG)"),
    "outcome_mismatches": ("1", "oblique cases whose outcome differs from the reference"),
    "e_n_reference": ("1", "reference e_n (DOP853, tightest rtol)"),
    "case": ("1", "index of the case"),
    "outcome_label": (None, "impact outcome: rebound or capture"),
    "failures": (None, "checks the case failed, as 'kind: detail' separated by '; ' (empty: none)"),
    "notes": (None, "findings that do not fail the case, as 'kind: detail' separated by '; ' (empty: none)"),
    "method": (None, "integration method"),
    "timing_mode": (None, "how the method was timed"),
}


#: other spellings of a unit -> the one UDUNITS style of :data:`VARIABLES`
UNIT_SPELLINGS: dict[str, str] = {
    "m/s": "m s-1", "m/s^2": "m s-2", "rad/s": "rad s-1", "1/s": "s-1", "N/m": "N m-1",
    "J/m^2": "J m-2", "J/m2": "J m-2", "kg/m^3": "kg m-3", "kg/m3": "kg m-3", "N*s": "N s", "N.s": "N s",
    "deg": "degree", "degrees": "degree", "-": "1",
}


def udunits(units: str) -> str:
    """``units`` in the toolkit's one UDUNITS style (``"m/s"`` -> ``"m s-1"``); others unchanged.

    Examples
    --------
    >>> udunits("m/s"), udunits("kg")
    ('m s-1', 'kg')
    """
    return UNIT_SPELLINGS.get(str(units).strip(), str(units).strip())


def attributes(name: str, **extra) -> dict:
    """``{"units": ..., "long_name": ...}`` of ``name`` from :data:`VARIABLES`, updated by ``extra``.

    Raises
    ------
    KeyError
        If ``name`` is not in the table (add it there, once).

    Examples
    --------
    >>> attributes("e_n")["long_name"]
    'normal coefficient of restitution, Eq. (21)'
    """
    units, long_name = VARIABLES[name]
    return {**({} if units is None else {"units": units}), "long_name": long_name, **extra}


def variable(name: str, dims, values, **extra) -> tuple:
    """``(dims, values, attributes)``: a Dataset variable of ``name`` with its table attributes.

    Examples
    --------
    >>> dims, values, attrs = variable("e_n", "speed", [0.5])
    >>> dims, attrs["units"]
    ('speed', '1')
    """
    return (dims, values, attributes(name, **extra))
