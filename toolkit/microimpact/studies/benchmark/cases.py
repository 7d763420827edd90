"""The benchmark's test set and sizes: normal speeds, oblique cases, settings and targets."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from microimpact.dynamics import capture_velocity
from microimpact.presets import WALL_1990

__all__ = [
    "ALL_METHODS",
    "SCIPY_METHODS",
    "TARGET_ERROR",
    "TARGET_RATIO",
    "SINGLE_CALL_TARGET_RATIO",
    "TARGET_RATIO_AIM",
    "TARGET_THROUGHPUT_SECONDS",
    "BenchmarkConfig",
    "ObliqueCase",
    "level_rtol",
    "level_steps",
    "normal_speed_set",
    "oblique_cases",
]

SCIPY_METHODS = ("RK45", "DOP853", "LSODA", "Radau")
ALL_METHODS = ("engine", "engine_batch", "engine_family", "rkg") + SCIPY_METHODS

#: Targets of the brief (evaluated, not assumed)
TARGET_ERROR = 1e-8  # at this max e_n error ...
TARGET_RATIO = 300.0  # ... the engine must be at least this much faster than DOP853 (aim 1000)
TARGET_RATIO_AIM = 1000.0
TARGET_THROUGHPUT_SECONDS = 5.0  # for 100,000 oblique impacts through simulate_many
SINGLE_CALL_TARGET_RATIO = 500.0  # one simulate_impact call vs DOP853 at TARGET_ERROR (performance issue)


@dataclass(frozen=True)
class ObliqueCase:
    """One oblique impact of the test set.

    speed [m/s], incidence_deg [deg], azimuth_deg [deg]; spins as multiples of the rolling spin
    v sin(alpha) / r about (n, t, t') [-]; friction [-].

    Examples
    --------
    Spin given as a multiple of the rolling spin v sin(alpha) / r: one rolling spin about t' of a
    2 um sphere at 2 m/s and 30 deg is 2 * 0.5 / 2e-6 = 5e5 rad/s:

    >>> case = ObliqueCase(speed=2.0, incidence_deg=30.0, azimuth_deg=0.0, spin_n=0.0, spin_t=0.0,
    ...                    spin_tp=1.0, friction=0.15)
    >>> [round(w, 6) for w in case.omega(2e-6)]
    [0.0, 0.0, 500000.0]
    """

    speed: float
    incidence_deg: float
    azimuth_deg: float
    spin_n: float
    spin_t: float
    spin_tp: float
    friction: float

    def omega(self, radius: float) -> tuple[float, float, float]:
        """Spin (omega_n, omega_t, omega_t') [rad/s] of a sphere of ``radius`` [m]."""
        w = self.speed * math.sin(math.radians(self.incidence_deg)) / radius
        return (self.spin_n * w, self.spin_t * w, self.spin_tp * w)


_OBLIQUE = (
    # speed, incidence, azimuth, spin_n, spin_t, spin_t', friction
    ObliqueCase(3.0, 10.0, 0.0, 0.0, 0.0, 0.0, 0.15),  # rebound, sliding throughout
    ObliqueCase(5.0, 30.0, 0.0, 0.0, 0.0, 1.0, 0.5),  # rebound, back-spin doubles the slip
    ObliqueCase(10.0, 60.0, 0.0, 0.5, 0.0, 10.0, 0.5),  # rebound, 10x spin + twist
    ObliqueCase(2.0, 45.0, 0.0, 0.0, 0.0, 0.0, 0.5),  # v_n = 1.41 m/s: captured, slip ends
    ObliqueCase(3.0, 70.0, 0.0, 1.0, 0.0, 0.0, 0.5),  # captured, with twist
    ObliqueCase(1.6, 10.0, 0.0, 0.0, 0.0, 0.0, 0.5),  # rebound just above capture
    ObliqueCase(20.0, 80.0, 0.0, 0.0, 0.0, -10.0, 0.15),  # rebound, large top-spin
    ObliqueCase(5.0, 45.0, 30.0, 0.0, 0.0, 0.0, 0.15),  # rebound, azimuth 30 deg
    ObliqueCase(50.0, 45.0, 90.0, 1.0, 3.0, 0.0, 0.5),  # rebound, spin about t, azimuth 90
    ObliqueCase(1.2, 10.0, 0.0, 0.0, 0.0, 2.0, 0.15),  # captured, spin
    ObliqueCase(100.0, 30.0, 45.0, 1.0, 1.0, 1.0, 0.15),  # rebound, all spins, azimuth 45
    ObliqueCase(8.0, 80.0, 0.0, 0.0, 0.0, -1.0, 0.5),  # captured, rolling (no slip)
)
_OBLIQUE_QUICK = tuple(_OBLIQUE[i] for i in (0, 1, 2, 3, 4, 5))


@dataclass(frozen=True)
class BenchmarkConfig:
    """Sizes of the benchmark. ``BenchmarkConfig.full()`` and ``.quick_()`` are the two presets.

    Setting k of the adaptive methods is rtol = 10^-(4+k) (:func:`level_rtol`); setting k of the
    Runge-Kutta-Gill method is N = 25 * 2^k steps per contact (:func:`level_steps`).
    ``time_limit`` [s] is the time per impact after which a scipy setting and the tighter ones
    are dropped; an oblique case over ``oblique_time_limit`` [s] is marked timed out (and said
    so in the notes); ``reference_rtols`` are the loose and the tight rtol of the reference.

    Examples
    --------
    The quick preset measures fewer speeds and every other setting of the engine:

    >>> quick, full = BenchmarkConfig.quick_(), BenchmarkConfig.full()
    >>> (quick.n_speeds, quick.engine_levels), (full.n_speeds, len(full.engine_levels))
    ((6, (0, 2, 4, 6, 8)), (10, 9))
    """

    quick: bool
    n_speeds: int
    max_speed: float
    capture_margin: float
    engine_levels: tuple
    scipy_levels: tuple
    rkg_levels: tuple
    oblique: tuple
    repeats_single: int
    repeats_scipy: int
    repeats_batch: int
    batch_size: int
    throughput_impacts: int
    throughput_repeats: int
    memory_sizes: tuple
    time_limit: float
    oblique_time_limit: float = 12.0
    reference_rtols: tuple = (1e-12, 1e-13)
    #: engine_family: distinct normal speeds per evaluation; impacts of the family target and how
    #: many of them are checked against tight direct solves
    family_size: int = 100_000
    family_impacts: int = 1_000_000
    family_check: int = 20_000
    #: batch sizes whose peak memory growth is compared with the output's (family path)
    family_memory_sizes: tuple = (100_000, 1_000_000)
    #: also judge the engine_family line on the oblique cases (a family over their range: seconds)
    family_oblique: bool = True
    #: rows of the large fit compared with a 100-row fit
    fit_rows: int = 100_000
    contact_name: str = "WALL_1990"
    notes: tuple = field(default_factory=tuple)

    @classmethod
    def full(cls) -> "BenchmarkConfig":
        """The full benchmark (docs/benchmark.md; several minutes)."""
        return cls(
            quick=False, n_speeds=10, max_speed=100.0, capture_margin=1.02,
            engine_levels=tuple(range(9)), scipy_levels=tuple(range(7)), rkg_levels=tuple(range(9)),
            oblique=_OBLIQUE, repeats_single=15, repeats_scipy=3, repeats_batch=5, batch_size=4000,
            throughput_impacts=100_000, throughput_repeats=3, memory_sizes=(10_000, 100_000), time_limit=3.0,
        )

    @classmethod
    def quick_(cls) -> "BenchmarkConfig":
        """A small benchmark for CI and the workflow."""
        return cls(
            quick=True, n_speeds=6, max_speed=100.0, capture_margin=1.02,
            engine_levels=(0, 2, 4, 6, 8), scipy_levels=(0, 2, 4), rkg_levels=(0, 2, 4, 6),
            oblique=_OBLIQUE_QUICK, repeats_single=5, repeats_scipy=1, repeats_batch=3, batch_size=1000,
            throughput_impacts=20_000, throughput_repeats=1, memory_sizes=(2_000, 20_000), time_limit=1.0,
            oblique_time_limit=0.25,  # RK45 takes far longer to settle a captured case: quick marks it timed out
            reference_rtols=(1e-11, 1e-12), family_size=20_000, family_impacts=100_000, family_check=3_000,
            family_memory_sizes=(20_000, 200_000), fit_rows=10_000, family_oblique=False,
        )

    @classmethod
    def tiny_(cls) -> "BenchmarkConfig":
        """A benchmark of about a second, for examples: two normal speeds, one oblique case, the
        loosest setting of each method, loose time limits (a slow solve is not cut short).

        Examples
        --------
        >>> c = BenchmarkConfig.tiny_()
        >>> c.n_speeds, len(c.oblique), c.n_settings
        (2, 1, 1)
        """
        return dataclasses.replace(
            cls.quick_(), n_speeds=2, max_speed=10.0, engine_levels=(0,), scipy_levels=(0,), rkg_levels=(0,),
            oblique=_OBLIQUE_QUICK[:1], repeats_single=1, repeats_batch=1, batch_size=10, family_size=10,
            time_limit=5.0, oblique_time_limit=12.0, reference_rtols=(1e-8, 1e-9))

    @property
    def n_settings(self) -> int:
        """Length of the ``setting`` dimension: the largest level of any method plus one."""
        return max(max(self.engine_levels), max(self.scipy_levels), max(self.rkg_levels)) + 1


def level_rtol(k: int) -> float:
    """rtol of setting k for the adaptive methods: 10^-(4+k). [-]

    Examples
    --------
    >>> level_rtol(0), level_rtol(4)
    (0.0001, 1e-08)
    """
    return 10.0 ** -(4 + k)


def level_steps(k: int) -> int:
    """Steps per contact of setting k for the Runge-Kutta-Gill method: 25 * 2^k.

    Examples
    --------
    >>> [level_steps(k) for k in range(4)]
    [25, 50, 100, 200]
    """
    return 25 * 2**k


def normal_speed_set(contact=WALL_1990, n: int = 10, max_speed: float = 100.0, margin: float = 1.02):
    """``n`` normal speeds log-spaced from ``margin`` times the capture speed to ``max_speed``.

    Returns
    -------
    speeds : numpy.ndarray
        The test speeds. [m/s]
    capture_speed : float
        Capture velocity of a normal impact, :func:`microimpact.dynamics.capture_velocity` to
        1e-12 relative with engine solves at rtol 1e-12. [m/s]

    Examples
    --------
    Four speeds from just above the capture speed of the 1990 wall sphere (1.449 m/s) to 100 m/s:

    >>> speeds, v_cap = normal_speed_set(n=4)
    >>> round(v_cap, 4), round(float(speeds[0] / v_cap), 6), float(speeds[-1])
    (1.4492, 1.02, 100.0)
    """
    v_cap = capture_velocity(contact, xtol=0.0, rtol=1e-12, solver_rtol=1e-12)
    return np.geomspace(margin * v_cap, max_speed, n), v_cap


def oblique_cases(quick: bool = False) -> tuple:
    """The oblique test cases (:class:`ObliqueCase`), six of them in quick mode.

    Examples
    --------
    >>> len(oblique_cases(quick=True)) < len(oblique_cases())
    True
    >>> oblique_cases(quick=True)[0].incidence_deg
    10.0
    """
    return _OBLIQUE_QUICK if quick else _OBLIQUE
