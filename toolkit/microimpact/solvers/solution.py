"""The one result type of every normal solve, and the one of every batch of solves.

Every solver of one normal impact returns a :class:`NormalSolution` (SI units), whatever integrates
it: the compiled driver's laws (the paper's ring law, :mod:`~microimpact.solvers.engine`; JKR, DMT and Hertz with a DEM
damping, :mod:`~microimpact.solvers.normal_models`; Thornton & Ning, :mod:`~microimpact.solvers.thornton_ning_law`), the paper's
Runge-Kutta-Gill method (:mod:`~microimpact.solvers.rkg`) and the independent scipy references
(:func:`~microimpact.solvers.normal_models.solve_normal_reference`,
:func:`~microimpact.solvers.reference.reference_trajectory`,
:func:`~microimpact.solvers.plastic_reference.plastic_impact`). It says why the solve stopped
(:attr:`NormalSolution.stop_reason`, one of :data:`STOP_REASONS`); what only one law has (the
plastic state of Thornton & Ning, the energy along a reference trajectory) is in its ``state``, a
read-only mapping of named values, not in fields of a second type.

Every solver of many impacts returns a :class:`SolutionBatch`: one array per quantity, one element
per impact (the compiled batches of the engine and of the JKR/DMT/Hertz solver, the coupled
solver of tangential compliance, the RKG batch, a family's evaluation). A quantity a solver does
not compute is None and is not among the batch's names. :meth:`SolutionBatch.to_dataset` gives
it as an xarray Dataset, each variable with its ``units`` and ``long_name``.

The design follows PyBaMM's solution object, which states why its solver stopped [1]_.

References
----------
.. [1] Sulzer, V., Marquis, S. G., Timms, R., Robinson, M. & Chapman, S. J. (2021). Python Battery
   Mathematical Modelling (PyBaMM). J. Open Res. Softw. 9, 14, doi:10.5334/jors.309.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from types import MappingProxyType

import numpy as np

__all__ = ["NormalSolution", "SolutionBatch", "STOP_REASONS", "BATCH_UNITS", "frozen_state"]

#: Why a solve stopped:
#:
#: * ``"separation"``: the sphere left the surface (a rebound);
#: * ``"capture"``: the contact energy fell below the capture threshold and the solve ended there
#:   (or at the captured sphere's turning point, for an undamped plastic law);
#: * ``"settled"``: a captured sphere was followed until its oscillation, or the friction and twist
#:   impulses still to come, were below the tolerance;
#: * ``"duration"``: the requested duration ended in contact (a reference trajectory);
#: * ``"max_steps"``, ``"step_underflow"``: the step budget was spent, or the step size fell below
#:   the law's floor (a solver that does not raise on them says so here).
STOP_REASONS = ("separation", "capture", "settled", "duration", "max_steps", "step_underflow")

#: [units, long_name] of every quantity a batch can hold (the variables of :meth:`SolutionBatch.to_dataset`)
BATCH_UNITS: dict[str, tuple[str, str]] = {
    "captured": ("1", "captured (1) or rebounded (0)"),
    "e_n": ("1", "normal restitution coefficient"),
    "contact_time": ("s", "contact duration (inf if captured)"),
    "capture_time": ("s", "time at which the contact energy fell below the capture threshold"),
    "max_penetration": ("m", "largest penetration"),
    "friction_impulse": ("N s", "friction impulse int |F_n| dt (or of the friction load)"),
    "twist_impulse": ("N m s", "twist impulse int a |F_n| dt"),
    "dissipated_energy": ("J", "energy removed by the normal contact"),
    "final_energy": ("J", "normal kinetic plus contact energy at the end"),
    "slip_end_time": ("s", "time at which sliding ended"),
    "n_steps": ("1", "accepted integration steps"),
    "v_t": ("m s-1", "tangential velocity after the impact"),
    "v_tp": ("m s-1", "second tangential velocity after the impact"),
    "omega_n": ("rad s-1", "normal angular velocity after the impact"),
    "omega_t": ("rad s-1", "tangential angular velocity after the impact"),
    "omega_tp": ("rad s-1", "second tangential angular velocity after the impact"),
    "slip_ended": ("1", "sliding ended during contact"),
    "turning_points": ("1", "turning points of a hysteretic tangential law"),
    "tangential_error": ("m s-1", "error estimate of the final tangential velocity of a held sphere"),
    "not_determined": ("1", "tangential outcome not determined to its tolerance"),
}


def frozen_state(values: Mapping | None = None) -> Mapping:
    """A read-only copy of ``values`` (the ``state`` of a :class:`NormalSolution`).

    Examples
    --------
    >>> s = frozen_state({"plastic_radius": 1e-6})
    >>> s["plastic_radius"]
    1e-06
    >>> s["work"] = 0.0
    Traceback (most recent call last):
    ...
    TypeError: 'mappingproxy' object does not support item assignment
    """
    return MappingProxyType(dict(values or {}))


@dataclass(frozen=True)
class NormalSolution:
    """One normal impact, solved (SI units): the result of every single-impact normal solver.

    Attributes
    ----------
    outcome : str
        "rebound", "capture", or "in contact" (a trajectory whose duration ended first).
    e_n : float
        Normal restitution coefficient, Eq. (21); 0 if captured. [-]
    contact_time : float
        Duration of contact; inf if captured. [s]
    capture_time : float
        Time at which the contact energy first fell below the capture threshold; NaN for a
        rebound. [s]
    max_penetration : float
        Largest penetration x = -n (the approach delta). [m]
    friction_impulse : float
        J = int |F_n| dt over the contact; for a captured sphere over the part integrated; NaN where
        the solver does not integrate it. [N s]
    twist_impulse : float
        J_a = int a |F_n| dt, which drives the twist friction torque; NaN where not integrated. [N m s]
    dissipated_energy : float
        Energy the normal contact removed (damping; adhesion hysteresis and plastic work where the
        law has them). [J]
    final_energy : float
        Normal kinetic plus contact energy at the end (m v_out^2/2 for a rebound). [J]
    slip_end_time : float
        Time at which J reached the requested ``friction_impulse_target``; NaN if not reached or
        not requested. [s]
    n_steps, n_rejected : int
        Accepted and rejected integration steps.
    stop_reason : str
        Why the solve stopped, one of :data:`STOP_REASONS`.
    time, penetration, penetration_rate : numpy.ndarray or None
        Trajectory at the solver's steps, when asked for. [s], [m], [m/s]
    state : Mapping
        What only this law has, by name (read-only): for Thornton & Ning the plastic state of the
        unloading curve (``plastic_radius`` [m], ``plastic_approach`` [m], ``yielded``, ...) and
        the work of the contact force ``work`` [J]; for a reference trajectory ``energy`` and
        ``dissipated`` along it [J]. Empty for the other laws.

    Examples
    --------
    The paper's microsphere at 2 m/s rebounds: of the incident kinetic energy it keeps e_n^2, and
    that plus what the damping dissipated is all of it:

    >>> from microimpact.presets import WALL_1990 as c
    >>> from microimpact.solvers.engine import solve_normal
    >>> s = solve_normal(c, 2.0)
    >>> kinetic = 0.5 * c.mass * 2.0**2
    >>> s.outcome, s.stop_reason, round(s.final_energy / kinetic - s.e_n**2, 12)
    ('rebound', 'separation', 0.0)
    >>> round((s.final_energy + s.dissipated_energy) / kinetic, 6), dict(s.state), s.captured
    (1.0, {}, False)
    """

    outcome: str
    e_n: float
    contact_time: float
    capture_time: float
    max_penetration: float
    friction_impulse: float
    twist_impulse: float
    dissipated_energy: float
    final_energy: float
    slip_end_time: float
    n_steps: int
    n_rejected: int
    stop_reason: str
    time: np.ndarray | None = None
    penetration: np.ndarray | None = None
    penetration_rate: np.ndarray | None = None
    state: Mapping = field(default_factory=frozen_state)

    def __post_init__(self):
        if self.stop_reason not in STOP_REASONS:
            raise ValueError(f"NormalSolution.stop_reason must be one of {', '.join(STOP_REASONS)}, "
                             f"got {self.stop_reason!r}")
        if not isinstance(self.state, MappingProxyType):
            object.__setattr__(self, "state", frozen_state(self.state))

    @property
    def captured(self) -> bool:
        """True if the sphere was captured (``outcome == "capture"``)."""
        return self.outcome == "capture"


@dataclass(frozen=True, eq=False)
class SolutionBatch(Mapping):
    """Many impacts, solved (SI arrays, one element per impact): the result of every batch solver.

    A quantity the solver does not compute is None; the batch reads as a mapping of the others
    (``batch["e_n"]``, ``list(batch)``, ``batch.items()``), in the order of the attributes.

    Attributes
    ----------
    captured : numpy.ndarray of bool
    e_n : numpy.ndarray
        Normal restitution coefficient; 0 if captured (NaN where a fixed-step solve found no
        outcome). [-]
    contact_time, capture_time : numpy.ndarray
        As in :class:`NormalSolution`. [s]
    max_penetration : numpy.ndarray
        [m]
    friction_impulse, twist_impulse : numpy.ndarray
        [N s], [N m s]
    dissipated_energy, final_energy : numpy.ndarray
        [J]
    slip_end_time : numpy.ndarray
        [s]
    n_steps : numpy.ndarray of int
        Steps of each solve (0 where a family interpolated it).
    v_t, v_tp, omega_n, omega_t, omega_tp : numpy.ndarray
        Velocities [m/s] and angular velocities [rad/s] after the impact (coupled solver).
    slip_ended : numpy.ndarray of bool
    turning_points : numpy.ndarray of int
        Turning points of a hysteretic tangential law.
    tangential_error : numpy.ndarray
        Error estimate of the final tangential velocity of a captured sphere held by friction with
        rolling resistance, else 0. [m/s]
    not_determined : numpy.ndarray of bool
        That estimate exceeds the coupled solver's tolerance.

    Examples
    --------
    >>> import numpy as np
    >>> b = SolutionBatch(captured=np.array([False, True]), e_n=np.array([0.5, 0.0]), n_steps=np.array([40, 90]))
    >>> list(b), b["e_n"] is b.e_n, len(b), b.twist_impulse is None
    (['captured', 'e_n', 'n_steps'], True, 3, True)
    >>> ds = b.to_dataset()
    >>> ds["e_n"].attrs["units"], ds["captured"].dims, ds.attrs["stop_reason"]
    ('1', ('impact',), 'separation capture')
    >>> b.stop_reason.tolist()
    ['separation', 'capture']
    """

    captured: np.ndarray
    e_n: np.ndarray
    contact_time: np.ndarray | None = None
    capture_time: np.ndarray | None = None
    max_penetration: np.ndarray | None = None
    friction_impulse: np.ndarray | None = None
    twist_impulse: np.ndarray | None = None
    dissipated_energy: np.ndarray | None = None
    final_energy: np.ndarray | None = None
    slip_end_time: np.ndarray | None = None
    n_steps: np.ndarray | None = None
    v_t: np.ndarray | None = None
    v_tp: np.ndarray | None = None
    omega_n: np.ndarray | None = None
    omega_t: np.ndarray | None = None
    omega_tp: np.ndarray | None = None
    slip_ended: np.ndarray | None = None
    turning_points: np.ndarray | None = None
    tangential_error: np.ndarray | None = None
    not_determined: np.ndarray | None = None

    def _present(self) -> tuple[str, ...]:
        return tuple(f.name for f in fields(self) if getattr(self, f.name) is not None)

    def __getitem__(self, name: str):
        value = getattr(self, name, None) if not name.startswith("_") else None
        if value is None or name not in BATCH_UNITS:
            raise KeyError(name)
        return value

    def __iter__(self):
        return iter(self._present())

    def __len__(self) -> int:
        return len(self._present())

    @property
    def stop_reason(self) -> np.ndarray:
        """Why each solve stopped: "separation" or "capture" (a batch solver raises on the others)."""
        return np.where(np.asarray(self.captured, dtype=bool), "capture", "separation")

    def to_dataset(self, dim: str = "impact"):
        """The batch as an xarray Dataset along ``dim``, each variable with ``units`` and ``long_name``."""
        import xarray as xr  # on first use: 0.2 s of start-up that a batch solve itself never needs

        data = {name: (dim, np.asarray(self[name]), {"units": BATCH_UNITS[name][0], "long_name": BATCH_UNITS[name][1]})
                for name in self}
        return xr.Dataset(data, attrs={"stop_reason": " ".join(STOP_REASONS[:2])})
