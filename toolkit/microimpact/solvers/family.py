"""A family of impacts: the normal-solve outputs of one contact as functions of the normal speed.

A sweep, a fit or a set of flags over N impacts of one contact is a one-parameter family in the
incident normal speed v_n: the restitution e_n, the contact (or capture) time, the largest
penetration, the friction and twist impulses and the dissipated energy are smooth functions of
v_n except where the outcome changes (the capture speed v_c). :func:`normal_family` computes them
at adaptively chosen nodes and interpolates them, so N impacts cost a few hundred normal solves
plus N cheap evaluations instead of N solves.

Method
------
* **Branches.** A log-spaced scan of the speed range finds where the outcome changes; each change
  is located by multisection to 1e-14 relative (the capture speed). The range is split there into
  rebound and capture branches, so no piece straddles the jump.
* **Pieces.** Each branch is cut into pieces at most ``PIECE_WIDTH`` wide in ln v_n. On each piece
  every output is interpolated by a Chebyshev polynomial of degree ``DEGREE`` in ln v_n through
  the Chebyshev-Lobatto nodes (adjacent pieces share end nodes). Positive outputs that span
  decades (times, penetration, impulses) are interpolated as logarithms, so the tolerance on them
  is relative; e_n and the dissipated fraction D / (m v_n^2 / 2) are interpolated as they are,
  with an absolute tolerance.
* **Verified bound.** Each piece is checked against direct solves at ``CHECKS`` points that are
  not nodes (midway, in angle, between Chebyshev nodes, where the interpolation error of a
  Lobatto interpolant peaks). A piece whose error exceeds half the tolerance is halved, and the
  check is repeated on the halves.
* **The capture speed.** The outputs have fractional-power singularities at v_c (a sphere that
  barely escapes lingers at the edge of the contact; e_n ~ (v_n - v_c)^(1/2), the contact time
  has a (v_n - v_c)^(1/6) term). Halving converges geometrically towards v_c; a piece narrower
  than ``GUARD`` (relative width in v_n) that still fails is marked *direct*: impacts that fall in
  it are solved directly, so the family is never less accurate than its tolerance. Such guard
  bands hold a fraction of about 1e-7 of a range. For a known number N of impacts the guard
  widens to ``GUARD_IMPACTS / N`` of the range in ln v_n: halving a piece costs 2 (DEGREE + 1 +
  CHECKS) = 42 node solves, each about as costly there as a direct solve, so solving the few
  impacts expected in the piece directly is cheaper (the million-impact benchmark batch: 1,409
  instead of 2,291 node solves and 36 impacts solved directly; 10 to 40 measured alike). A
  batch crowded at the capture speed costs more direct solves, never accuracy.
* **Captured impacts.** Node solves of the capture branch follow the captured oscillation until
  the friction impulse still to come is below the tolerance (``need_tail``), so the family's J and
  J_a are the totals over the whole settling. The closed-form tangential map takes min(J, J*), so
  the tangential outcome is exact to the tolerance whatever the stop impulses are; the direct
  path instead stops early once every impact of a speed has stopped sliding and twisting, which
  gives the same outcome but a smaller recorded J for captured impacts.

The node solves use ``rtol / 100`` (not below 1e-13), so the node values are more accurate than
the interpolation tolerance ``rtol``; with the default ``rtol = 1e-8`` the family's e_n agrees with
direct solves at rtol 1e-12 to about 1e-9 (tests/test_family.py, docs/benchmark.md).
"""

from __future__ import annotations

import math
import mmap
from dataclasses import dataclass, field
from types import MappingProxyType

import numba
import numpy as np
from numba import prange

from microimpact._numba import njit, njit_batch
from microimpact.model.coefficients import coefficients_kernel
from microimpact.model.law import contact_potential_energy
from microimpact.model.tangential import tangential_kernel
from microimpact.solvers import DEFAULT_RTOL, SolverError, engine
from microimpact.solvers.solution import SolutionBatch

__all__ = ["FamilyImpacts", "NormalFamily", "normal_family", "normal_restitution", "FamilyBudgetExceeded", "DEGREE", "GUARD", "GUARD_IMPACTS",
           "FAMILY_MIN_SPEEDS"]

#: from this many distinct normal speeds on, :func:`normal_restitution` and
#: :func:`microimpact.simulate_many` consider the interpolated family (a family costs a few hundred
#: to a few thousand normal solves, docs/benchmark.md)
FAMILY_MIN_SPEEDS = 2000

#: degree of the Chebyshev interpolant on each piece
DEGREE = 16
#: check points per piece (not nodes)
CHECKS = 4
#: widest piece, in ln v_n (a factor e^0.5 = 1.65 in speed)
PIECE_WIDTH = 0.5
#: narrowest piece, relative width in v_n: narrower failing pieces are solved directly
GUARD = 1e-7
#: with N impacts, a failing piece narrower than GUARD_IMPACTS / N of the range (in ln v_n) is
#: solved directly: about this many impacts fall in it if they spread evenly over ln v_n
GUARD_IMPACTS = 20.0
#: relative precision of the capture speed (multisection)
CAPTURE_PRECISION = 1e-14
#: tightest rtol of the node solves (used for the capture speed and for pieces near it)
NODE_RTOL_FLOOR = 1e-13
#: pieces within this distance in ln v_n of a capture speed (1 %) use NODE_RTOL_FLOOR
NEAR_CAPTURE = 0.01

#: outputs interpolated on each piece: (name, interpolated as log)
_OUTPUTS = (("e_n_squared", False), ("time", True), ("max_penetration", True), ("friction_impulse", True),
            ("twist_impulse", True), ("dissipated_fraction", False))


class FamilyBudgetExceeded(SolverError):
    """The family would need more normal solves than the budget (solving directly is cheaper).

    A budget of solves, not of time (that is :class:`microimpact.solvers.TimeBudgetExceeded`, the
    package's one time-budget error): a :class:`~microimpact.solvers.SolverError`, so the solvers'
    errors are one hierarchy.

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> normal_family(c, 2.0, 20.0, max_solves=5)
    Traceback (most recent call last):
    ...
    microimpact.solvers.family.FamilyBudgetExceeded: the family needs more than 5 normal solves
    """


def _lobatto_matrix(n: int) -> np.ndarray:
    """Matrix taking values at the n+1 Chebyshev-Lobatto points cos(pi k / n) to the Chebyshev
    coefficients of the interpolant (a DCT-I)."""
    k = np.arange(n + 1)
    m = np.cos(np.pi * np.outer(k, k) / n) * (2.0 / n)
    m[:, 0] *= 0.5
    m[:, -1] *= 0.5
    m[0, :] *= 0.5
    m[-1, :] *= 0.5
    return m


_NODES = np.cos(np.pi * np.arange(DEGREE + 1) / DEGREE)  # from +1 down to -1
_TO_COEFFICIENTS = _lobatto_matrix(DEGREE)
#: check points: midway in angle between Lobatto nodes, spread over the piece
_CHECK_POINTS = np.cos(np.pi * (np.linspace(0, DEGREE - 1, CHECKS).round() + 0.5) / DEGREE)


@njit(cache=True)
def _clenshaw(c, t):
    b1 = 0.0
    b2 = 0.0
    for j in range(c.shape[0] - 1, 0, -1):
        b1, b2 = 2.0 * t * b1 - b2 + c[j], b1
    return t * b1 - b2 + c[0]


@njit(cache=True)
def _clenshaw6(c, t):
    """:func:`_clenshaw` of the six series c[0..5] at once. The recurrence is a chain of dependent
    multiply-adds, so one series at a time waits on each step's latency; six interleaved chains
    keep the floating-point units busy."""
    a0 = a1 = a2 = a3 = a4 = a5 = 0.0
    b0 = b1 = b2 = b3 = b4 = b5 = 0.0
    t2 = 2.0 * t
    for j in range(c.shape[1] - 1, 0, -1):
        a0, b0 = t2 * a0 - b0 + c[0, j], a0
        a1, b1 = t2 * a1 - b1 + c[1, j], a1
        a2, b2 = t2 * a2 - b2 + c[2, j], a2
        a3, b3 = t2 * a3 - b3 + c[3, j], a3
        a4, b4 = t2 * a4 - b4 + c[4, j], a4
        a5, b5 = t2 * a5 - b5 + c[5, j], a5
    return (t * a0 - b0 + c[0, 0], t * a1 - b1 + c[1, 0], t * a2 - b2 + c[2, 0],
            t * a3 - b3 + c[3, 0], t * a4 - b4 + c[4, 0], t * a5 - b5 + c[5, 0])


@njit_batch
def _evaluate(x, piece, left, right, coefficients, out):
    for i in prange(x.shape[0]):
        p = piece[i]
        if p < 0:
            continue
        t = (2.0 * x[i] - left[p] - right[p]) / (right[p] - left[p])
        for q in range(coefficients.shape[1]):
            out[i, q] = _clenshaw(coefficients[p, q], t)


@dataclass(frozen=True)
class FamilyImpacts:
    """Whole impacts of :meth:`NormalFamily.impacts`.

    Attributes
    ----------
    columns : Mapping of str to ndarray
        One flat array per :data:`BATCH_VARIABLES` name (SI; the outcome as its code); the rows of
        the impacts in ``in_band`` are not filled.
    in_band : ndarray of bool
        The impacts in a guard band at the capture speed, which the caller solves directly.
    """

    columns: object
    in_band: np.ndarray


#: columns of :func:`_impacts_kernel`'s output, in order (the variables of simulate_many)
BATCH_VARIABLES = ("outcome", "e_n", "mu_t", "mu_tp", "K_L", "K_t", "velocity_out_n", "velocity_out_t",
                   "velocity_out_tp", "omega_out_n", "omega_out_t", "omega_out_tp", "contact_time",
                   "max_penetration", "slip_ended", "friction_impulse", "dissipated_energy")


@njit_batch
def normal_speed_range(speed, incidence_deg):
    """(smallest, largest) incident normal speed v cos(incidence) of a batch [m/s, deg] in one
    pass, without the batch-sized temporaries of the numpy expression."""
    lo, hi = math.inf, -math.inf
    for i in prange(speed.shape[0]):
        v_n = speed[i] * math.cos(math.radians(incidence_deg[i]))
        lo, hi = min(lo, v_n), max(hi, v_n)
    return lo, hi


@njit(cache=True, inline="always")
def _piece_of(edges, x):
    lo, hi = 0, edges.shape[0] - 2
    while lo < hi:  # the last piece whose left edge is <= x
        mid = (lo + hi + 1) // 2
        if edges[mid] <= x:
            lo = mid
        else:
            hi = mid - 1
    return lo


@njit_batch
def _impacts_kernel(speed, incidence_deg, azimuth_deg, w_n, w_t, w_tp, friction, edges, captured, direct,
                    coefficients, mass, inertia, radius, settled_energy, out, solve_directly):
    """Whole impacts from the family in one compiled pass: incident kinematics, the interpolated
    normal outputs, the closed-form tangential map and Eqs. (21)-(25), for every impact whose
    normal speed is not in a guard band (those are flagged in ``solve_directly``)."""
    for i in prange(speed.shape[0]):
        a = math.radians(incidence_deg[i])
        th = math.radians(azimuth_deg[i])
        v_n = -speed[i] * math.cos(a)
        v_t = speed[i] * math.sin(a) * math.cos(th)
        v_tp = speed[i] * math.sin(a) * math.sin(th)
        x = math.log(-v_n)
        p = _piece_of(edges, x)
        solve_directly[i] = direct[p]
        if direct[p]:
            continue
        t = min(max((2.0 * x - edges[p] - edges[p + 1]) / (edges[p + 1] - edges[p]), -1.0), 1.0)
        q0, q1, q2, q3, q4, q5 = _clenshaw6(coefficients[p], t)
        cap = captured[p]
        e_n = 0.0 if cap else math.sqrt(min(max(q0, 0.0), 1.0))
        jn, ja = math.exp(q3), math.exp(q4)
        tan = tangential_kernel(mass, inertia, radius, friction[i], v_t, v_tp, w_n[i], w_t[i], w_tp[i], jn, ja)
        vn_out = 0.0 if cap else -e_n * v_n
        coef = coefficients_kernel(mass, inertia, v_n, v_t, v_tp, w_n[i], w_t[i], w_tp[i],
                                   vn_out, tan[0], tan[1], tan[2], tan[3], tan[4], cap)
        kinetic = 0.5 * mass * v_n * v_n
        normal_loss = kinetic - settled_energy if cap else q5 * kinetic
        row = (1.0 if cap else 0.0, coef[0], coef[1], coef[2], coef[3], coef[4], vn_out, tan[0], tan[1],
               tan[2], tan[3], tan[4], math.inf if cap else math.exp(q1), math.exp(q2),
               1.0 if tan[5] else 0.0, jn, normal_loss + tan[7])
        for k in range(17):
            out[k, i] = row[k]


def _fresh_array(shape) -> np.ndarray:
    """An uninitialised float64 array in its own anonymous memory map.

    numpy asks Linux for transparent huge pages on large arrays (madvise); where the kernel then
    compacts memory on the first touch of each page (THP defrag "madvise", the common default),
    writing a fresh output of hundreds of megabytes is markedly slower than in plain pages. The
    map is released with the last array that views it."""
    n = int(np.prod(shape))
    if n * 8 < (1 << 24):  # below 16 MB: numpy's allocator, no huge pages involved
        return np.empty(shape)
    return np.frombuffer(mmap.mmap(-1, n * 8), dtype=np.float64).reshape(shape)


def _node_values(contact, speed, captured_branch: bool, rtol: float) -> tuple[np.ndarray, np.ndarray]:
    """The interpolated outputs (rows of _OUTPUTS) at the given speeds, logs of the positive ones,
    and where the outcome is not the branch's (a second outcome change the scan missed)."""
    # the batch is split between the threads in contiguous blocks, and the costly solves (near a
    # capture speed, long captured tails) cluster in speed: dealt out in turn, each thread gets
    # its share of them (a faster build on 2 threads)
    order = np.argsort(np.arange(speed.size) % numba.get_num_threads(), kind="stable")
    dealt = engine.solve_normal_many(contact, speed[order], np.full(speed.shape, captured_branch), rtol=rtol,
                                     tail_tolerance=rtol)
    sol = {k: np.empty_like(v) for k, v in dealt.items()}
    for k, v in dealt.items():
        sol[k][order] = v
    kinetic = 0.5 * contact.mass * speed * speed
    # the capture time (when the contact energy first falls below zero) jumps where the first
    # negative energy moves to a later oscillation; it is not a smooth output and is not interpolated
    time = np.ones(speed.shape) if captured_branch else sol["contact_time"]
    with np.errstate(divide="ignore"):
        return np.stack([sol["e_n"] ** 2, np.log(time), np.log(sol["max_penetration"]), np.log(sol["friction_impulse"]),
                         np.log(sol["twist_impulse"]), sol["dissipated_energy"] / kinetic]), sol["captured"] != captured_branch


@dataclass(frozen=True)
class NormalFamily:
    """The normal-solve outputs of one contact over a range of normal speeds, interpolated.

    Attributes
    ----------
    contact : Contact
    speed_range : tuple of float
        Smallest and largest normal speed covered. [m/s]
    rtol : float
        Tolerance of the interpolation (absolute for e_n and the dissipated fraction, relative for
        the others), verified at non-node points of every piece. [-]
    node_rtol : float
        Tolerance of the node solves away from capture speeds (near them, and in the guard bands,
        NODE_RTOL_FLOOR). [-]
    capture_speeds : tuple of float
        Normal speeds at which the outcome changes inside the range (the capture speed). [m/s]
    edges : numpy.ndarray
        Piece edges in ln v_n, shape (P + 1,). [-]
    captured : numpy.ndarray
        Per piece, whether it is a capture branch piece (bool).
    direct : numpy.ndarray
        Per piece, whether its impacts are solved directly (a guard band at a capture speed).
    coefficients : numpy.ndarray
        Chebyshev coefficients, shape (P, outputs, DEGREE + 1).
    n_solves : int
        Normal solves spent building and checking the family.
    max_check_error : float
        Largest error found at the check points of the accepted pieces, in tolerance units
        (absolute or relative as above). [-]
    restitution_only : bool
        Only e_n (and the outcome) is interpolated; the other outputs are NaN.

    Examples
    --------
    A family of a damped Hertz contact over 1-10 m/s interpolates the direct solves within its
    tolerance:

    >>> import numpy as np
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> from microimpact.solvers.engine import solve_normal_many
    >>> h = c.with_(adhesion_line_force=0.0, zeta_adhesion=0.0)
    >>> fam = normal_family(h, 1.0, 10.0, rtol=1e-6)
    >>> v = np.array([1.5, 3.0, 7.0])
    >>> error = np.abs(fam.evaluate(v)["e_n"] - solve_normal_many(h, v)["e_n"])
    >>> fam.capture_speeds, bool(np.max(error) < 1e-6)
    ((), True)
    """

    contact: object
    speed_range: tuple
    rtol: float
    node_rtol: float
    capture_speeds: tuple
    edges: np.ndarray = field(repr=False)
    captured: np.ndarray = field(repr=False)
    direct: np.ndarray = field(repr=False)
    coefficients: np.ndarray = field(repr=False)
    n_solves: int = 0
    max_check_error: float = 0.0
    restitution_only: bool = False

    @property
    def n_pieces(self) -> int:
        return int(self.captured.size)

    def describe(self) -> str:
        """One line for a result's ``normal_solve_path`` attribute."""
        return (f"family: {self.n_pieces} Chebyshev pieces of degree {DEGREE} in ln v_n, {self.n_solves} normal "
                f"solves, tolerance {self.rtol:g} verified at non-node points (largest check error "
                f"{self.max_check_error:.2g} of it), {int(self.direct.sum())} guard band(s) solved directly")

    def evaluate(self, normal_speed) -> SolutionBatch:
        """The outputs at ``normal_speed`` (1-D array within :attr:`speed_range`) [m/s].

        Returns the :class:`~microimpact.solvers.solution.SolutionBatch` of
        :func:`microimpact.solvers.engine.solve_normal_many` (``n_steps`` is 0 for interpolated
        speeds); for a captured impact J and J_a are totals over the settling.
        """
        v = np.ascontiguousarray(normal_speed, dtype=float).ravel()
        lo, hi = self.speed_range
        if v.size and (v.min() < lo * (1 - 1e-12) or v.max() > hi * (1 + 1e-12)):
            raise ValueError(f"normal speeds must lie in the family's range [{lo!r}, {hi!r}] m/s")
        x = np.log(v)
        piece = np.clip(np.searchsorted(self.edges, x, side="right") - 1, 0, self.n_pieces - 1)
        use_direct = self.direct[piece]
        values = np.zeros((v.size, len(_OUTPUTS)))
        _evaluate(x, np.where(use_direct, -1, piece), self.edges[:-1].copy(), self.edges[1:].copy(),
                  self.coefficients, values)
        return self._assemble(v, piece, use_direct, values)

    def impacts(self, speed, incidence_deg, azimuth_deg, w_n, w_t, w_tp, friction) -> FamilyImpacts:
        """Whole impacts (flat float arrays; speed [m/s], angles [deg], spins [rad/s], friction [-])
        in one compiled pass: the :class:`FamilyImpacts` (a read-only column per
        :data:`BATCH_VARIABLES` name and the mask of the impacts in a guard band, whose rows the
        caller must fill by direct solves)."""
        if self.restitution_only:
            raise ValueError("a restitution_only family has no impulses for the tangential map")
        c = self.contact
        n = speed.size
        out = _fresh_array((len(BATCH_VARIABLES), n))
        solve_directly = np.zeros(n, dtype=np.bool_)
        _impacts_kernel(speed, incidence_deg, azimuth_deg, w_n, w_t, w_tp, friction, self.edges, self.captured,
                        self.direct, self.coefficients, c.mass, c.moment_of_inertia, c.radius,
                        engine_settled_energy(c), out, solve_directly)
        return FamilyImpacts(MappingProxyType(dict(zip(BATCH_VARIABLES, out))), solve_directly)

    def _assemble(self, v, piece, use_direct, values) -> SolutionBatch:
        c = self.contact
        captured = self.captured[piece]
        kinetic = 0.5 * c.mass * v * v
        e_n = np.where(captured, 0.0, np.sqrt(np.clip(values[:, 0], 0.0, 1.0)))
        time = np.exp(values[:, 1])
        settled = float(engine_settled_energy(c))
        out = {
            "captured": captured,
            "e_n": e_n,
            "contact_time": np.where(captured, np.inf, time),
            "capture_time": np.full(v.size, np.nan),  # not interpolated (see _node_values)
            "max_penetration": np.exp(values[:, 2]),
            "friction_impulse": np.exp(values[:, 3]),
            "twist_impulse": np.exp(values[:, 4]),
            "dissipated_energy": values[:, 5] * kinetic,
            "final_energy": np.where(captured, settled, kinetic * e_n * e_n),
            "n_steps": np.zeros(v.size, dtype=np.int64),
        }
        if self.restitution_only:  # not interpolated
            for k in ("contact_time", "max_penetration", "friction_impulse", "twist_impulse", "dissipated_energy",
                      "final_energy"):
                out[k] = np.full(v.size, np.nan)
        if np.any(use_direct):
            idx = np.flatnonzero(use_direct)
            # guard bands lie at capture speeds, where the nodes use the tightest tolerance too
            sol = engine.solve_normal_many(c, v[idx], np.ones(idx.size, dtype=bool), rtol=NODE_RTOL_FLOOR,
                                           tail_tolerance=NODE_RTOL_FLOOR)
            for k, val in sol.items():
                out[k][idx] = val
        return SolutionBatch(**out)


def engine_settled_energy(contact) -> float:
    """Contact energy of a sphere at rest at the adhesive equilibrium (0 without adhesion). [J]"""
    if contact.adhesion_line_force <= 0.0:
        return 0.0
    return float(contact_potential_energy(contact, contact.length_scale))


def _capture_brackets(contact, lo: float, hi: float, rtol: float) -> list[tuple[float, float]]:
    """Brackets (a, b) in [lo, hi] of relative width CAPTURE_PRECISION across which the outcome
    changes (a capture speed); a and b have the outcomes of the branches below and above."""
    n_scan = max(9, int(4 * math.log(hi / lo)) + 1)
    v = np.geomspace(lo, hi, n_scan)
    cap = engine.solve_normal_many(contact, v, rtol=rtol)["captured"]
    brackets = [(v[i], v[i + 1]) for i in np.flatnonzero(cap[1:] != cap[:-1])]
    found = []
    for a, b in brackets:
        cap_a = bool(cap[np.searchsorted(v, a)])
        while b - a > CAPTURE_PRECISION * b:
            trial = np.linspace(a, b, 17)[1:-1]
            c = engine.solve_normal_many(contact, trial, rtol=rtol)["captured"]
            changed = np.flatnonzero(c != cap_a)
            i = int(changed[0]) if changed.size else trial.size
            a, b = (trial[i - 1] if i > 0 else a), (trial[i] if i < trial.size else b)
        found.append((a, b))
    return found


def normal_family(contact, speed_min: float, speed_max: float, *, rtol: float = DEFAULT_RTOL,
                  max_solves: int | None = None, restitution_only: bool = False,
                  n_impacts: int | None = None) -> NormalFamily:
    """Build the interpolated family of normal solves of ``contact`` over [speed_min, speed_max].

    Parameters
    ----------
    contact : Contact
    speed_min, speed_max : float
        Range of incident normal speeds to cover, 0 < speed_min <= speed_max. [m/s]
    rtol : float
        Interpolation tolerance, verified at non-node points (see the module docstring). [-]
    max_solves : int, optional
        Budget of normal solves; :class:`FamilyBudgetExceeded` when building needs more.
    restitution_only : bool
        Interpolate e_n only (a fit): the other outputs are not checked (NaN from
        :meth:`NormalFamily.evaluate`), and capture branches, where e_n = 0, cost no solves.
    n_impacts : int, optional
        How many impacts the family will serve: the guard bands widen to ``GUARD_IMPACTS /
        n_impacts`` of the range (see the module docstring). Default: the narrowest, GUARD.

    Returns
    -------
    NormalFamily

    References
    ----------
    Cheng, Brach & Dunn (2002), Eq. (27)

    Dormand & Prince (1980)

    Examples
    --------
    Above the paper's capture velocity (1.449 m/s) the family interpolates the direct solves; below
    it every impact is captured:

    >>> import numpy as np
    >>> from microimpact.presets import get_preset
    >>> from microimpact.solvers.engine import solve_normal_many
    >>> c = get_preset("wall1990")
    >>> fam = normal_family(c, 2.0, 10.0)
    >>> v = np.array([2.5, 5.0, 9.0])
    >>> out = fam.evaluate(v)
    >>> out["captured"].tolist(), fam.capture_speeds
    ([False, False, False], ())
    >>> bool(np.max(np.abs(out["e_n"] - solve_normal_many(c, v)["e_n"])) < 1e-7)
    True
    >>> normal_family(c, 0.2, 1.0).evaluate([0.5])["captured"].tolist()
    [True]
    """
    if contact.normal_model != "ring" or contact.damping_model != "paper":
        raise ValueError("normal_family interpolates the paper's ring normal law with the paper's damping, got "
                         f"normal_model={contact.normal_model!r}, damping_model={contact.damping_model!r}")
    lo, hi = float(speed_min), float(speed_max)
    if not (0.0 < lo <= hi and math.isfinite(hi)):
        raise ValueError(f"need 0 < speed_min <= speed_max (finite), got {speed_min!r}, {speed_max!r}")
    node_rtol = max(rtol / 100.0, NODE_RTOL_FLOOR)
    hi = max(hi, lo * (1.0 + 1e-9))  # one speed: a tiny piece around it
    # the capture speed at the tightest tolerance: e_n ~ (v_n - v_c)^(1/2) makes the e_n of a
    # rebound just above v_c as sensitive to v_c as 1 / (v_n - v_c)
    brackets = _capture_brackets(contact, lo, hi, NODE_RTOL_FLOOR)
    guard = GUARD if not n_impacts else max(GUARD, math.expm1(GUARD_IMPACTS * math.log(hi / lo) / n_impacts))
    builder = _Builder(contact, rtol, node_rtol, max_solves, restitution_only, guard)
    starts = [lo] + [b for _, b in brackets]
    ends = [a for a, _ in brackets] + [hi]
    for a, b in zip(starts, ends):
        builder.add_branch(a, b)
    for a, b in brackets:  # the bracket of a capture speed itself is solved directly
        builder.done.append((math.log(a), math.log(b), False, True, np.zeros((len(_OUTPUTS), DEGREE + 1))))
    splits = [0.5 * (a + b) for a, b in brackets]
    builder.capture_logs = [math.log(x) for x in splits]
    pieces = builder.run()
    edges = np.array([p[0] for p in pieces] + [pieces[-1][1]])
    return NormalFamily(
        contact=contact, speed_range=(lo, hi), rtol=rtol, node_rtol=node_rtol, capture_speeds=tuple(splits),
        edges=edges, captured=np.array([p[2] for p in pieces], dtype=bool),
        direct=np.array([p[3] for p in pieces], dtype=bool),
        coefficients=np.stack([p[4] for p in pieces]),
        n_solves=builder.n_solves + 0, max_check_error=builder.worst, restitution_only=restitution_only)


class _Builder:
    """Adaptive refinement of the pieces, one batch of normal solves per level (both cores)."""

    def __init__(self, contact, rtol, node_rtol, max_solves, restitution_only=False, guard=GUARD):
        self.contact, self.rtol, self.node_rtol, self.max_solves = contact, rtol, node_rtol, max_solves
        self.guard = guard  # relative width in v_n below which a failing piece is solved directly
        self.checked = [0] if restitution_only else list(range(len(_OUTPUTS)))  # rows held to rtol
        self.todo = []  # (left, right, captured) in ln v
        self.done = []  # (left, right, captured, direct, coefficients)
        self.n_solves = 0
        self.worst = 0.0
        self.capture_logs = []  # ln of the capture speeds

    def add_branch(self, a: float, b: float) -> None:
        mid = math.sqrt(a * b)
        captured = bool(engine.solve_normal_many(self.contact, np.array([mid]), rtol=self.node_rtol)["captured"][0])
        self.n_solves += 1
        xa, xb = math.log(a), math.log(b)
        if captured and self.checked == [0]:  # e_n = 0 on a capture branch: nothing to solve
            self.done.append((xa, xb, True, False, np.zeros((len(_OUTPUTS), DEGREE + 1))))
            return
        n = max(1, math.ceil((xb - xa) / PIECE_WIDTH))
        cuts = np.linspace(xa, xb, n + 1)
        self.todo += [(cuts[i], cuts[i + 1], captured) for i in range(n)]

    def run(self) -> list:
        while self.todo:
            batch, self.todo = self.todo, []
            self._level(batch)
        return sorted(self.done, key=lambda p: p[0])

    def _level(self, batch) -> None:
        for captured in (False, True):
            for near in (False, True):
                pieces = [p for p in batch if p[2] == captured and self._near_capture(p) == near]
                if pieces:
                    self._solve_pieces(pieces, captured, NODE_RTOL_FLOOR if near else self.node_rtol)

    def _near_capture(self, piece) -> bool:
        """Whether a rebound piece lies within NEAR_CAPTURE (in ln v_n) of a capture speed, where
        e_n's sensitivity to the capture speed, 1 / (v_n - v_c), calls for the tightest node solves
        (e_n is 0 on the capture side)."""
        return not piece[2] and any(piece[0] - NEAR_CAPTURE <= x <= piece[1] + NEAR_CAPTURE for x in self.capture_logs)

    def _solve_pieces(self, pieces, captured, node_rtol) -> None:
        left = np.array([p[0] for p in pieces])[:, None]
        right = np.array([p[1] for p in pieces])[:, None]
        half = 0.5 * (right - left)
        points = np.hstack([left + half * (1.0 + _NODES), left + half * (1.0 + _CHECK_POINTS)])
        n = points.size
        if self.max_solves is not None and self.n_solves + n > self.max_solves:
            raise FamilyBudgetExceeded(f"the family needs more than {self.max_solves} normal solves")
        values, other = _node_values(self.contact, np.exp(points.ravel()), captured, node_rtol)
        values = values.reshape(len(_OUTPUTS), *points.shape)
        other = other.reshape(points.shape).any(axis=1)
        self.n_solves += n
        for i, (a, b, cap) in enumerate(pieces):
            self._accept_or_split(a, b, cap, values[:, i, :DEGREE + 1], values[:, i, DEGREE + 1:], other[i])

    def _accept_or_split(self, a, b, captured, at_nodes, at_checks, mixed) -> None:
        coefficients = at_nodes @ _TO_COEFFICIENTS.T
        predicted = np.array([[_clenshaw(c, t) for t in _CHECK_POINTS] for c in coefficients])
        predicted[0] = np.sqrt(np.clip(predicted[0], 0.0, 1.0))  # e_n from e_n^2, compared as e_n
        at_checks = at_checks.copy()
        at_checks[0] = np.sqrt(at_checks[0])
        finite = np.isfinite(at_checks) & np.isfinite(predicted)
        err = np.where(finite, np.abs(predicted - at_checks), np.where(at_checks == predicted, 0.0, np.inf))[self.checked]
        worst = math.inf if mixed else float(err.max()) / self.rtol
        if worst <= 0.5:
            self.worst = max(self.worst, worst)
            self.done.append((a, b, captured, False, coefficients))
        elif math.expm1(b - a) < self.guard:
            self.done.append((a, b, captured, True, coefficients))
        else:
            m = 0.5 * (a + b)
            self.todo += [(a, m, captured), (m, b, captured)]


def normal_restitution(contact, normal_speed, *, rtol: float = DEFAULT_RTOL, family: bool | None = None) -> np.ndarray:
    """e_n at many normal speeds [m/s] (a fit's model): one direct engine solve per distinct speed,
    or, for many distinct speeds, a restitution-only family (``family`` None chooses, True/False
    force) when it costs fewer than half as many solves. [-]

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (21) and (27)

    Dormand & Prince (1980)

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2 as c
    >>> normal_restitution(c, [10.0, 30.0]).round(6).tolist()
    [0.715808, 0.735996]
    """
    v = np.asarray(normal_speed, dtype=float).ravel()
    if contact.normal_model != "ring" or contact.damping_model != "paper":  # their own solver, one solve per speed
        from microimpact.solvers import normal_models  # imported on use: it compiles its own kernels

        return normal_models.solve_normal_many(contact, v, rtol=rtol)["e_n"]
    if family or (family is None and v.size >= FAMILY_MIN_SPEEDS):
        speeds, inverse = np.unique(v, return_inverse=True)
        if family or speeds.size >= FAMILY_MIN_SPEEDS:
            try:
                fam = normal_family(contact, float(speeds[0]), float(speeds[-1]), rtol=rtol, restitution_only=True,
                                    max_solves=None if family else speeds.size // 2, n_impacts=speeds.size)
                return fam.evaluate(speeds)["e_n"][inverse]
            except FamilyBudgetExceeded:
                pass
    return engine.solve_normal_many(contact, v, rtol=rtol)["e_n"]
