"""An error-controlled emulator of the ring law's restitution over its nondimensional groups.

The normal impact of the paper's ring law depends on three groups only (:mod:`microimpact.model.reduction`):
y0 = v T / X, C1 = C_H X / T and C2 = C_A X / T (Eqs. (28), (31)-(32)). So e_n and the outcome of
any number of contacts is one function of three variables, built once, cached on disk, and evaluated
in a compiled kernel; where its verified error is above the tolerance asked for, the solver runs
instead. :func:`restitution` is the entry point.

Method
------
* **Coordinates.** a = ln C1, b = ln C2 over the box :data:`DOMAIN`; in each (a, b) the speed
  coordinate t = sqrt(ln(y0 / y_c) / ln(Y_max / y_c)) in [0, 1] above the capture speed y_c(C1, C2).
  Below y_c the sphere is captured (e_n = 0). Just above it e_n rises like a root,
  e_n ~ (y0 - y_c)^(1/2) (a sphere that barely escapes leaves with the energy it has left, linear in
  y0 - y_c); in t that root is a smooth factor t, so e_n is interpolated in t as it is.
* **The capture surface.** y_c is found at each node by a log scan of :data:`SCAN` speeds (which
  also proves one outcome change only) and multisection to relative width :data:`CAPTURE_WIDTH`, and
  ln y_c is a tensor Chebyshev interpolant of degree :data:`DEGREE_SURFACE` on each (a, b) cell. Its error
  is measured at :data:`CELL_CHECKS` random points of the cell against new multisections; a cell
  whose surface misses :func:`surface_tolerance` is split into four (a quadtree, at most
  :data:`MAX_DEPTH` levels) and a leaf that still misses is left to the solver.
* **e_n.** On each cell, [0, 1] in t is cut into pieces (halved where needed); on each piece a tensor
  Chebyshev interpolant of degree :data:`DEGREE_AB` x :data:`DEGREE_AB` x :data:`DEGREE_T` through
  Lobatto nodes. Each piece is checked at points that are not nodes: in t at random (a, b) nodes
  (a failing piece is halved; one narrower than :data:`MIN_PIECE` is left to the solver) and in (a, b)
  at the cell's check points (a failing cell is split; a failing piece near capture,
  :data:`NEAR_CAPTURE_T`, or in a cell at :data:`MAX_DEPTH`, is left to the solver alone). The
  largest error seen on a piece, times :data:`SAFETY`, is its error estimate.
* **Node and check solves.** Near capture a solve's e_n error is ~1.2 rtol / e_n (the energy left at
  separation has an absolute error ~ rtol and e_n is its square root), so the nodes are solved at
  :data:`NODE_RTOL` tol (1e-12 for tol 1e-8) and the checks :data:`CHECK_RTOL_FACTOR` tighter still:
  checks at the nodes' own rtol share the nodes' bias and cannot see it.
* **The guard band.** Between y_c (1 - g) and y_c (1 + g) the outcome and the root are too sensitive
  to the surface's error eps: there the solver runs. g = max(SAFETY eps, (SAFETY eps / tol)^2)
  bounds the error of the root (e_n error ~ eps / (2 sqrt(g)) just above the band).
* **Fallback.** Impacts outside the domain (C1, C2 or y0, also C1 = 0 or C2 = 0), in the band, in a
  piece or cell left to the solver, or whose piece's estimate exceeds ``tol``, are solved
  (:func:`microimpact.solvers.family.normal_restitution`), per contact, at ``rtol = tol / 100``;
  those whose e_n comes out below :data:`NEAR_CAPTURE_E` again at ``tol e_n / 12``
  (:data:`FALLBACK_RTOL`). Why they fall back is counted by :meth:`RingEmulator.fallback_reasons`.
* **Limits.** Within ~ (rtol_min / tol)^2 of y_c in ln y0 (rtol_min the solvers' MIN_RTOL; e_n below
  ~3e-6 at tol 1e-8) no solve resolves e_n to ``tol``: that sliver, a share ~1e-12 of log-uniform
  speeds, is beyond the error control.

The table is built once per tolerance and cached outside the install tree (:func:`cache_dir`, like
numba's cache): an ``.npz`` whose name carries the tolerance, the domain, the degrees and a hash of
the model's and this module's source, so that an edited law never reads a stale table. The tables
of :data:`SHIPPED` (a few hundred kB) come with the package (:func:`shipped_dir`), so that a fresh
install does not build them; :func:`ship_tables` writes them, and a test fails when a change of the
sources leaves a shipped table stale.

References
----------
Cheng, W., Brach, R. M. and Dunn, P. F. (2002), Aerosol Sci. Technol. 36:1081-1093, Eqs. (27)-(32).

Trefethen, L. N. (2013), Approximation Theory and Approximation Practice, SIAM, chapters 2-8
(Chebyshev interpolation through Lobatto points and its convergence).
"""

from __future__ import annotations

import hashlib
import math
import os
from dataclasses import dataclass, field
from importlib.resources import files
from pathlib import Path

import numpy as np

from microimpact._numba import njit
from microimpact.model import reduction
from microimpact.model.contact import Contact
from microimpact.solvers import MIN_RTOL, engine_threads
from microimpact.solvers.family import normal_restitution

__all__ = ["DOMAIN", "EXAMPLE_DOMAIN", "DEFAULT_TOLERANCE", "SHIPPED", "WIDE_DOMAIN", "Restitution", "RingEmulator",
           "build_ring_emulator", "cache_dir", "ring_emulator", "restitution", "ship_tables", "shipped_dir",
           "surface_tolerance", "table_tolerance", "fallback_restitution"]

#: the groups' box the table covers: C1, C2 and y0 ranges [-]; outside it the solver runs. It holds
#: the paper's microsphere (Table 1 row 2: C1 = 2.5e-3 to 6e-3, C2 = 0.15 to 0.37, y0 = 0.08 to 80 over
#: 0.1 to 100 m/s). Above C2 ~ 0.5 the capture speed steepens towards the damping at which nothing
#: rebounds, and quarter-decade cells of degree DEGREE_SURFACE no longer meet the surface tolerance
#: (a build over C2 up to 1 left C2 > 0.56 to the solver).
DOMAIN = {"hertz_damping": (1e-3, 1e-2), "adhesion_damping": (0.1, 0.5), "incident_speed": (1e-2, 1e3)}
#: a one-cell box for examples and quick tests (C1 over a factor 2, C2 over a factor 2) [-]
EXAMPLE_DOMAIN = {"hertz_damping": (1e-3, 2e-3), "adhesion_damping": (0.1, 0.2), "incident_speed": (1e-2, 1e2)}
#: absolute tolerance on e_n of :func:`restitution` by default [-]
DEFAULT_TOLERANCE = 1e-6
#: :data:`DOMAIN` with C2 down to 0.03: the fastest impacts of micrometre spheres (C2 falls as
#: v^(-1/5); C2 ~ 0.09 at 23 m/s for the paper's microsphere) are in it rather than solved [-]
WIDE_DOMAIN = dict(DOMAIN) | {"adhesion_damping": (0.03, 0.5)}
#: the tables that come with the package, as (table tolerance, domain): the posterior's
#: (:data:`microimpact.analysis.posterior.EMULATOR_TOLERANCE` over :data:`WIDE_DOMAIN`)
SHIPPED = ((1e-6, WIDE_DOMAIN),)
#: Chebyshev degree of the capture surface ln y_c in ln C1 and ln C2 per cell (y_c grows steeply
#: towards the damping at which nothing rebounds: its coefficients fall by ~0.1 per degree on a
#: quarter decade), of e_n in ln C1 and ln C2, and of e_n in t per piece
DEGREE_SURFACE, DEGREE_AB, DEGREE_T = 12, 6, 12
#: root cells per decade of C1 and C2
CELLS_PER_DECADE = 1
#: deepest quadtree level below a root cell (at tol 1e-8 level 2 left the fastest pieces, t > 0.75, of
#: four of its 16 cells to the solver, 2-3 % of the benchmark's impacts; level 3 none)
MAX_DEPTH = 3
#: random (a, b) check points per cell (surface and e_n), and t check points per piece and node
CELL_CHECKS, T_CHECKS = 4, 4
#: (a, b) nodes per piece at which t is checked
T_CHECK_NODES = 3
#: initial pieces in t, and the narrowest piece halving makes before the solver takes over
INITIAL_PIECES, MIN_PIECE = 4, 1e-4
#: speeds of the capture scan over the y0 range, speeds per multisection round, and the relative
#: width multisection stops at
SCAN, SECTIONS, CAPTURE_WIDTH = 17, 4, 1e-10
#: factor from the largest check error to the error estimate
SAFETY = 2.0
#: tolerance of the node solves (rtol) relative to the table's, its floor, and its ceiling (a node
#: just above y_c must have the outcome right). Near capture a solve's e_n error grows like
#: ~1.2 rtol / e_n (the energy left at separation carries an absolute error ~ rtol, and
#: e_n ~ sqrt of it; measured against rtol 1e-13), so rtol = 1e-2 tol would miss tol wherever
#: e_n < 1e-2: 1e-4 tol keeps the nodes within 1e-2 tol down to e_n ~ 1e-2.
NODE_RTOL, NODE_RTOL_FLOOR, NODE_RTOL_CEILING = 1e-4, 1e-12, 1e-10
#: the check solves run this much tighter than the nodes, so that a bias the nodes share with
#: solves at their own rtol (the ~rtol / e_n error near capture) shows as check error
CHECK_RTOL_FACTOR = 0.1
#: a piece of e_n ending below this t (ln(y0 / y_c) below 1/1024 of the speed range) that misses the
#: tolerance at the (a, b) checks is left to the solver instead of splitting its cell: there the
#: error is the root's sensitivity to the surface and the node solves (~ eps / sqrt(ln(y0 / y_c))),
#: which a split does not cure, and the piece holds a share ~ 1e-3 of the speeds
NEAR_CAPTURE_T = 1.0 / 32.0
#: the solver's rtol where the table leaves an impact to it, relative to ``tol``; a solve whose e_n
#: comes out below :data:`NEAR_CAPTURE_E` (error ~1.2 rtol / e_n, NODE_RTOL) is redone at
#: ``tol`` e_n / 12 (at least the solvers' MIN_RTOL), so that its error stays ~ tol / 10
FALLBACK_RTOL, NEAR_CAPTURE_E = 1e-2, 0.12
#: tolerance of the outcome solves of the capture multisection (at most; finer for a table finer than
#: 1e-6: 1e-3 of :func:`surface_tolerance`), and CAPTURE_WIDTH at most 1e-2 of it
CAPTURE_RTOL = 1e-11
#: cell and piece states
_OK, _CAPTURED, _SOLVE = 0, 1, 2
#: why the table leaves an impact to the solver (:meth:`RingEmulator.fallback_reasons`), by code 1..5
FALLBACK_REASONS = ("outside the domain", "cell left to the solver", "guard band about the capture speed",
                    "piece left to the solver", "piece estimate above tol")
#: the version of the table's layout (part of the cache key)
_LAYOUT = 1


def surface_tolerance(tol: float) -> float:
    """Largest error of ln y_c a cell accepts: 1e-2 tol, at most 1e-6, so that the guard band
    g = (SAFETY eps / tol)^2 stays below 4e-4 (module docstring). [-]

    Examples
    --------
    >>> surface_tolerance(1e-6)
    1e-08
    """
    return min(1e-2 * tol, 1e-6)


# --------------------------------------------------------------------------- canonical solves
def _canonical(c1, c2):
    """A contact whose impacts have the groups (C1, C2) at every speed (a fixed reference speed),
    and its speed unit X / T [m/s]. The sphere: 1 um, 1000 kg/m^3, K = 1e9 Pa, f0 = 1 N/m."""
    base = Contact(1e-6, 1000.0, 1e9, 1.0)
    u = base.length_scale / base.time_scale
    scale = base.damping_speed_scale * u**0.2  # C = zeta / scale at v_ref = u, Eqs. (14)-(15)
    return base.with_(zeta_hertz=c1 / u * scale, zeta_adhesion=c2 / u * scale, damping_reference_speed=u), u


def _solve(c1, c2, y0, rtol):
    """e_n at nondimensional speeds y0 of the groups (C1, C2); 0 where captured. [-]"""
    contact, u = _canonical(float(c1), float(c2))
    return normal_restitution(contact, np.asarray(y0, dtype=float) * u, rtol=max(rtol, MIN_RTOL * 1.01),
                              family=False)


def _capture_speed(c1, c2, y_range, width=None, rtol=None):
    """(y_c, state, solves): the capture speed of (C1, C2) in y_range and _OK; or (inf, _CAPTURED) if
    every scanned speed is captured; (nan, _SOLVE) if the scan sees more than one outcome change or
    a rebound at its lowest speed. ``width`` and ``rtol``: the multisection's relative width and its
    solves' tolerance (default CAPTURE_WIDTH, CAPTURE_RTOL)."""
    width = CAPTURE_WIDTH if width is None else width
    rtol = CAPTURE_RTOL if rtol is None else rtol
    y = np.geomspace(*y_range, SCAN)
    rebound = _solve(c1, c2, y, rtol) > 0.0
    n = y.size
    if not rebound.any():
        return math.inf, _CAPTURED, n
    if np.count_nonzero(np.diff(rebound)) != 1 or rebound[0]:
        return math.nan, _SOLVE, n
    i = int(np.argmax(rebound))
    lo, hi = y[i - 1], y[i]
    while hi / lo - 1.0 > width:
        y = np.geomspace(lo, hi, SECTIONS + 2)[1:-1]
        r = _solve(c1, c2, y, rtol) > 0.0
        n += y.size
        j = int(np.argmax(r)) if r.any() else y.size
        lo, hi = (y[j - 1] if j > 0 else lo), (y[j] if j < y.size else hi)
    return float(hi), _OK, n


# --------------------------------------------------------------------------- Chebyshev tools
def _lobatto(n):
    """The n + 1 Lobatto points cos(pi k / n) on [-1, 1], k = 0..n."""
    return np.cos(np.pi * np.arange(n + 1) / n)


def _values_to_coefficients(n):
    """Matrix taking values at the Lobatto points to Chebyshev coefficients (degree n)."""
    x = _lobatto(n)
    t = np.cos(np.outer(np.arange(n + 1), np.arccos(x)))  # T_j(x_k)
    w = np.ones(n + 1)
    w[0] = w[-1] = 0.5
    m = 2.0 / n * t * w[None, :]
    m[0] *= 0.5
    m[-1] *= 0.5
    return m


def _coefficients(values):
    """Tensor Chebyshev coefficients of values at the tensor Lobatto grid (any dimension)."""
    c = np.asarray(values, dtype=float)
    for axis in range(c.ndim):
        c = np.moveaxis(np.tensordot(_values_to_coefficients(c.shape[axis] - 1), np.moveaxis(c, axis, 0), axes=1), 0, axis)
    return c


def _local(x, lo, hi):
    return (2.0 * x - lo - hi) / (hi - lo)


# --------------------------------------------------------------------------- the table
@dataclass(frozen=True)
class Restitution:
    """e_n of many impacts from :func:`restitution`.

    Attributes
    ----------
    e_n : ndarray
        Normal restitution; 0 where captured. [-]
    captured : ndarray of bool
        Whether the sphere is captured.
    solved : ndarray of bool
        Which impacts the solver computed (outside the table or where its estimate exceeds the
        tolerance); the others come from the table.
    tolerance : float
        The absolute tolerance on e_n asked for. [-]
    """

    e_n: np.ndarray
    captured: np.ndarray
    solved: np.ndarray
    tolerance: float


@dataclass(frozen=True)
class RingEmulator:
    """The built table of the ring law's e_n over (C1, C2, y0) (module docstring).

    Attributes
    ----------
    tolerance : float
        The absolute e_n tolerance it was built for. [-]
    domain : dict
        :data:`DOMAIN` at build time. [-]
    n_solves : int
        Normal solves the build made (nodes, multisections and checks).
    max_check_error : float
        Largest error of e_n seen at the check points of accepted pieces. [-]
    """

    tolerance: float
    domain: dict
    n_solves: int
    max_check_error: float
    arrays: dict = field(repr=False)

    def evaluate(self, incident_speed, hertz_damping, adhesion_damping, tol=None):
        """(e_n, captured, needs_solve) at the groups (arrays of one shape). [-]

        ``needs_solve`` marks the points the table does not decide to ``tol`` (default its own):
        outside the domain, in the guard band about the capture speed, or where a piece's error
        estimate exceeds ``tol``.

        :func:`restitution` is the entry point that uses it (and its example runs it).
        """
        e, state = self._states(incident_speed, hertz_damping, adhesion_damping, tol)
        return e, state == _CAPTURED, state >= _SOLVE

    def fallback_reasons(self, incident_speed, hertz_damping, adhesion_damping, tol=None) -> dict:
        """How many of these points the table leaves to the solver, by reason (:data:`FALLBACK_REASONS`).

        :func:`restitution` is the entry point that uses the table (and its example runs it).
        """
        state = self._states(incident_speed, hertz_damping, adhesion_damping, tol)[1]
        codes = np.bincount(state.ravel().astype(np.int64), minlength=_SOLVE + len(FALLBACK_REASONS))
        return {name: int(codes[_SOLVE + k]) for k, name in enumerate(FALLBACK_REASONS)}

    def _states(self, incident_speed, hertz_damping, adhesion_damping, tol):
        """(e_n, state) at the groups: state _OK, _CAPTURED, or _SOLVE + k for reason k of FALLBACK_REASONS."""
        y0, c1, c2 = (np.ascontiguousarray(np.asarray(x, dtype=float).ravel()) for x in
                      np.broadcast_arrays(incident_speed, hertz_damping, adhesion_damping))
        shape = np.broadcast(incident_speed, hertz_damping, adhesion_damping).shape
        e, state = np.empty(y0.size), np.empty(y0.size, dtype=np.int8)
        a = self.arrays
        _evaluate_many(y0, c1, c2, float(self.tolerance if tol is None else tol), a["box"], a["roots"], a["children"],
                       a["leaf"], a["cell_state"], a["guard"], a["surface"], a["piece_start"],
                       a["piece_count"], a["piece_t"], a["piece_state"], a["piece_error"], a["piece_coef"], e, state)
        return e.reshape(shape), state.reshape(shape)


@njit(cache=True)
def _find_cell(a, b, box, roots, children, leaf):
    """The leaf cell holding (a, b) and its bounds; -1 outside the box."""
    a0, a1, b0, b1, na, nb = box[0], box[1], box[2], box[3], int(box[4]), int(box[5])
    if not (a0 <= a <= a1 and b0 <= b <= b1):
        return -1, 0.0, 0.0, 0.0, 0.0
    wa, wb = (a1 - a0) / na, (b1 - b0) / nb
    ia, ib = min(int((a - a0) / wa), na - 1), min(int((b - b0) / wb), nb - 1)
    lo_a, lo_b = a0 + ia * wa, b0 + ib * wb
    hi_a, hi_b = lo_a + wa, lo_b + wb
    node = roots[ia * nb + ib]
    while children[node, 0] >= 0:
        ma, mb = 0.5 * (lo_a + hi_a), 0.5 * (lo_b + hi_b)
        q = (1 if a >= ma else 0) + (2 if b >= mb else 0)
        if a >= ma:
            lo_a = ma
        else:
            hi_a = ma
        if b >= mb:
            lo_b = mb
        else:
            hi_b = mb
        node = children[node, q]
    return leaf[node], lo_a, hi_a, lo_b, hi_b


@njit(cache=True)
def _evaluate_many(y0, c1, c2, tol, box, roots, children, leaf, cell_state, guard, surface, piece_start,
                   piece_count, piece_t, piece_state, piece_error, piece_coef, e, state):
    """The table at each point: e, and state _OK, _CAPTURED or _SOLVE + k (module docstring).

    The points are grouped by cell, then by piece, and each sum runs over a group's points at once:
    sums of different points are independent, so the compiler vectorizes them (no fastmath; one
    point's own sum would chain every addition to the one before)."""
    cell_of, xa, xb, ly = _cells_of(y0, c1, c2, box, roots, children, leaf, cell_state, state, e)
    order, start = _grouped(cell_of, cell_state.size)
    piece_of, xt = np.full(y0.size, -1, dtype=np.int64), np.empty(y0.size)
    log_y_hi = math.log(box[7])
    band_lo, band_hi = np.log1p(-guard), np.log1p(guard)  # per cell, not per point
    for c in range(cell_state.size):
        idx = order[start[c]:start[c + 1]]
        if idx.size == 0:
            continue
        log_yc = _tensor2_at(surface[c], _rows(xa, idx, surface.shape[1]), _rows(xb, idx, surface.shape[2]))
        for q in range(idx.size):
            n = idx[q]
            if ly[n] <= log_yc[q] + band_lo[c]:
                state[n] = _CAPTURED
                continue
            if ly[n] < log_yc[q] + band_hi[c]:
                state[n] = _SOLVE + 2
                continue
            t = math.sqrt(min((ly[n] - log_yc[q]) / (log_y_hi - log_yc[q]), 1.0))
            for p in range(piece_start[c], piece_start[c] + piece_count[c]):
                if piece_t[p, 0] <= t <= piece_t[p, 1]:
                    if piece_state[p] != _OK:
                        state[n] = _SOLVE + 3
                    elif piece_error[p] > tol:
                        state[n] = _SOLVE + 4
                    else:
                        piece_of[n] = p
                        xt[n] = (2.0 * t - piece_t[p, 0] - piece_t[p, 1]) / (piece_t[p, 1] - piece_t[p, 0])
                    break
    order, start = _grouped(piece_of, piece_state.size)
    for p in range(piece_state.size):
        idx = order[start[p]:start[p + 1]]
        if idx.size == 0:
            continue
        coef = piece_coef[p]
        got = _tensor3_at(coef, _rows(xa, idx, coef.shape[0]), _rows(xb, idx, coef.shape[1]), _rows(xt, idx, coef.shape[2]))
        for q in range(idx.size):
            e[idx[q]], state[idx[q]] = got[q], _OK


@njit(cache=True)
def _cells_of(y0, c1, c2, box, roots, children, leaf, cell_state, state, e):
    """Each point's cell (-1: decided here, or not the table's) and its local (a, b) and ln y0;
    sets e = 0 and the state of the points outside the domain, in cells left to the solver or
    captured throughout."""
    cell_of, xa, xb, ly = np.full(y0.size, -1, dtype=np.int64), np.empty(y0.size), np.empty(y0.size), np.empty(y0.size)
    y_lo, y_hi = box[6], box[7]
    for n in range(y0.size):
        e[n], state[n] = 0.0, _SOLVE  # _SOLVE + k: reason k of FALLBACK_REASONS (0: outside the domain)
        if not (c1[n] > 0.0 and c2[n] > 0.0 and y_lo <= y0[n] <= y_hi):
            continue
        a, b = math.log(c1[n]), math.log(c2[n])
        cell, lo_a, hi_a, lo_b, hi_b = _find_cell(a, b, box, roots, children, leaf)
        if cell < 0:
            continue
        if cell_state[cell] == _SOLVE:
            state[n] = _SOLVE + 1
            continue
        if cell_state[cell] == _CAPTURED:
            state[n] = _CAPTURED
            continue
        cell_of[n] = cell
        xa[n], xb[n] = (2.0 * a - lo_a - hi_a) / (hi_a - lo_a), (2.0 * b - lo_b - hi_b) / (hi_b - lo_b)
        ly[n] = math.log(y0[n])
    return cell_of, xa, xb, ly


@njit(cache=True)
def _grouped(key, n_keys):
    """(order, start): the indices with key k (>= 0) are order[start[k]:start[k + 1]] (a counting sort)."""
    start = np.zeros(n_keys + 1, dtype=np.int64)
    for k in key:
        if k >= 0:
            start[k + 1] += 1
    start = np.cumsum(start)
    fill = start[:-1].copy()
    order = np.empty(start[-1], dtype=np.int64)
    for n in range(key.size):
        k = key[n]
        if k >= 0:
            order[fill[k]] = n
            fill[k] += 1
    return order, start


@njit(cache=True)
def _rows(x, idx, n):
    """T_k(x[idx[q]]) for k < n as an (n, len(idx)) array (the three-term recurrence, across points)."""
    out = np.empty((n, idx.size))
    for q in range(idx.size):
        out[0, q] = 1.0
        if n > 1:
            out[1, q] = x[idx[q]]
    for k in range(2, n):
        for q in range(idx.size):
            out[k, q] = 2.0 * out[1, q] * out[k - 1, q] - out[k - 2, q]
    return out


@njit(cache=True)
def _tensor2_at(c, ta, tb):
    """sum_ij c_ij ta[i, q] tb[j, q] for each point q."""
    m = ta.shape[1]
    out, w = np.zeros(m), np.empty(m)
    for j in range(c.shape[1]):
        w[:] = 0.0
        for i in range(c.shape[0]):
            cij = c[i, j]
            for q in range(m):
                w[q] += cij * ta[i, q]
        for q in range(m):
            out[q] += w[q] * tb[j, q]
    return out


@njit(cache=True)
def _tensor3_at(c, ta, tb, tt):
    """sum_ijk c_ijk ta[i, q] tb[j, q] tt[k, q] for each point q."""
    m = ta.shape[1]
    out, u = np.zeros(m), np.empty(m)
    for i in range(c.shape[0]):
        for j in range(c.shape[1]):
            u[:] = 0.0
            for k in range(c.shape[2]):
                cijk = c[i, j, k]
                for q in range(m):
                    u[q] += cijk * tt[k, q]
            for q in range(m):
                out[q] += u[q] * ta[i, q] * tb[j, q]
    return out


# --------------------------------------------------------------------------- the build
def _counted(builder, c1, c2, y0, rtol):
    builder.n_solves += np.size(y0)
    return _solve(c1, c2, y0, rtol)


def _map(nodes, lo, hi):
    return 0.5 * (lo + hi) + 0.5 * (hi - lo) * nodes


class _Builder:
    """Builds the table cell by cell (module docstring); the solves it made in ``n_solves``."""

    def __init__(self, tol, domain, seed=20261202):
        self.tol, self.domain = float(tol), dict(domain)
        self.y_range = tuple(float(y) for y in domain["incident_speed"])
        self.node_rtol = min(max(NODE_RTOL * self.tol, NODE_RTOL_FLOOR), NODE_RTOL_CEILING)
        self.check_rtol = max(CHECK_RTOL_FACTOR * self.node_rtol, MIN_RTOL * 1.01)
        # the multisection finer than the surface tolerance, its solves' outcomes finer still
        self.capture_width = min(CAPTURE_WIDTH, 1e-2 * surface_tolerance(self.tol))
        self.capture_rtol = min(CAPTURE_RTOL, max(1e-3 * surface_tolerance(self.tol), MIN_RTOL * 1.01))
        self.rng = np.random.default_rng(seed)
        self.n_solves, self.max_check_error = 0, 0.0
        self.cells, self.children, self.leaf, self.failures = [], [], [], []
        self.x_ab, self.x_t = _lobatto(DEGREE_AB), _lobatto(DEGREE_T)

    def capture_speed(self, a, b):
        yc, state, n = _capture_speed(math.exp(a), math.exp(b), self.y_range, self.capture_width, self.capture_rtol)
        self.n_solves += n
        return yc, state

    def failed(self, bounds, reason):
        """Record why a cell is split (or left to the solver): None."""
        self.failures.append((tuple(float(x) for x in bounds), reason))
        return None

    def node(self, bounds, depth):
        """The tree node of ``bounds`` = (a0, a1, b0, b1), split while its cell fails and depth allows."""
        index = len(self.children)
        self.children.append([-1, -1, -1, -1])
        self.leaf.append(-1)
        cell = self.cell(bounds, last=depth >= MAX_DEPTH)
        if cell is None and depth < MAX_DEPTH:
            a0, a1, b0, b1 = bounds
            am, bm = 0.5 * (a0 + a1), 0.5 * (b0 + b1)
            quads = ((a0, am, b0, bm), (am, a1, b0, bm), (a0, am, bm, b1), (am, a1, bm, b1))
            for q, sub in enumerate(quads):
                self.children[index][q] = self.node(sub, depth + 1)
            return index
        if cell is None:
            cell = {"state": _SOLVE, "guard": 0.0, "surface": np.zeros((DEGREE_SURFACE + 1,) * 2), "pieces": []}
        self.leaf[index] = len(self.cells)
        self.cells.append(cell)
        return index

    def cell(self, bounds, last=False):
        """The cell's table, or None where it must be split. A piece that misses the tolerance at the
        (a, b) checks is left to the solver if it lies near capture (:data:`NEAR_CAPTURE_T`) or the
        cell is ``last`` (at :data:`MAX_DEPTH`); any other such piece splits the cell."""
        a0, a1, b0, b1 = bounds
        x_s = _lobatto(DEGREE_SURFACE)
        found = [[self.capture_speed(a, b) for b in _map(x_s, b0, b1)] for a in _map(x_s, a0, a1)]
        states = {s for row in found for _, s in row}
        checks = [(self.rng.uniform(a0, a1), self.rng.uniform(b0, b1)) for _ in range(CELL_CHECKS)]
        exact = [self.capture_speed(a, b) for a, b in checks]
        if states == {_CAPTURED}:  # captured at every scanned speed: so at the checks too, or split
            if all(s == _CAPTURED for _, s in exact):
                return {"state": _CAPTURED, "guard": 0.0, "surface": np.zeros((DEGREE_SURFACE + 1,) * 2), "pieces": []}
            return self.failed(bounds, "captured at every node, not at every check point")
        if states != {_OK} or any(s != _OK for _, s in exact):
            return self.failed(bounds, "the outcome changes other than once over the speeds")
        surface = _coefficients(np.log(np.array([[y for y, _ in row] for row in found])))
        local = [(_local(a, a0, a1), _local(b, b0, b1)) for a, b in checks]
        eps = max(abs(np.polynomial.chebyshev.chebval2d(x, y, surface) - math.log(yc))
                  for (x, y), (yc, _) in zip(local, exact))
        if eps > surface_tolerance(self.tol):
            return self.failed(bounds, f"capture surface error {eps:.3g}")
        self.guard = max(SAFETY * eps, (SAFETY * eps / self.tol) ** 2, SAFETY * self.capture_width)
        guard = self.guard
        # the e_n nodes and their capture speeds, from the surface as the evaluation takes them
        self._nodes = (_map(self.x_ab, a0, a1), _map(self.x_ab, b0, b1))
        log_yc = np.polynomial.chebyshev.chebgrid2d(self.x_ab, self.x_ab, surface)
        pieces = self.pieces(log_yc)
        failing = self.check_ab(pieces, surface, local, checks, guard)
        if not last and any(pieces[p][1] > NEAR_CAPTURE_T for p in failing):
            return self.failed(bounds, "e_n between the (a, b) nodes")
        for p in failing:
            pieces[p] = (*pieces[p][:2], _SOLVE, math.inf, pieces[p][4])
        self.max_check_error = max([self.max_check_error] + [p[3] / SAFETY for p in pieces if p[2] == _OK])
        return {"state": _OK, "guard": guard, "surface": surface, "pieces": pieces}

    def node_values(self, log_yc, edges):
        """e_n at the tensor nodes of each piece in ``edges``: array (pieces, n_ab, n_ab, n_t)."""
        t = np.array([_map(self.x_t, t0, t1) for t0, t1 in edges])  # (pieces, n_t)
        out = np.empty((len(edges), DEGREE_AB + 1, DEGREE_AB + 1, DEGREE_T + 1))
        for i in range(DEGREE_AB + 1):
            for j in range(DEGREE_AB + 1):
                width = math.log(self.y_range[1]) - log_yc[i, j]
                y = np.exp(log_yc[i, j] + width * t * t)
                a, b = self.a_nodes[i], self.b_nodes[j]
                out[:, i, j, :] = np.where(t > 0.0, _counted(self, math.exp(a), math.exp(b), y.ravel(),
                                                             self.node_rtol).reshape(t.shape), 0.0)
        return out

    def pieces(self, log_yc):
        """The accepted pieces of a cell [(t0, t1, state, error, coefficients)], halving where t-checks fail."""
        pending, done = [(k / INITIAL_PIECES, (k + 1) / INITIAL_PIECES) for k in range(INITIAL_PIECES)], []
        while pending:
            values = self.node_values(log_yc, pending)
            nxt = []
            for edges, v in zip(pending, values):
                t_nodes = _map(self.x_t, *edges)
                if np.any((v == 0.0) & (t_nodes > 0.0)[None, None, :]):  # captured above y_c: a second change
                    done.append((*edges, _SOLVE, math.inf, np.zeros_like(v)))
                    continue
                coef = _coefficients(v)
                err = self.check_t(log_yc, edges, coef)
                if SAFETY * err <= self.tol:
                    done.append((*edges, _OK, SAFETY * err, coef))
                elif edges[1] - edges[0] < MIN_PIECE:
                    done.append((*edges, _SOLVE, SAFETY * err, coef))
                else:
                    mid = 0.5 * (edges[0] + edges[1])
                    nxt += [(edges[0], mid), (mid, edges[1])]
            pending = nxt
        return sorted(done, key=lambda p: p[0])

    def check_t(self, log_yc, edges, coef):
        """Largest error in t at T_CHECK_NODES random (a, b) nodes, at T_CHECKS angle midpoints."""
        n = DEGREE_T
        k = self.rng.choice(n, size=min(T_CHECKS, n), replace=False)
        x0 = np.cos(np.pi * (k + 0.5) / n)  # midway in angle between Lobatto nodes
        err = 0.0
        for _ in range(T_CHECK_NODES):
            i, j = self.rng.integers(DEGREE_AB + 1, size=2)
            width = math.log(self.y_range[1]) - log_yc[i, j]
            t = _map(x0, *edges)
            keep = width * t * t >= math.log1p(self.guard)  # the guard band is the solver's
            x, t = x0[keep], t[keep]
            if not t.size:
                continue
            exact = _counted(self, math.exp(self.a_nodes[i]), math.exp(self.b_nodes[j]),
                             np.exp(log_yc[i, j] + width * t * t), self.check_rtol)
            got = np.polynomial.chebyshev.chebval3d(np.full(t.size, self.x_ab[i]), np.full(t.size, self.x_ab[j]), x, coef)
            err = max(err, float(np.max(np.abs(got - exact))))
        return err

    def check_ab(self, pieces, surface, local, checks, guard):
        """At the cell's check points, the table against solves at each piece's nodes (outside the
        guard band): the indices of the accepted pieces that miss the tolerance (the others'
        estimates updated)."""
        failing = set()
        x_t = np.concatenate([self.x_t, np.cos(np.pi * (np.arange(DEGREE_T) + 0.5) / DEGREE_T)])
        for (x, y), (a, b) in zip(local, checks):
            log_yc = float(np.polynomial.chebyshev.chebval2d(x, y, surface))
            width = math.log(self.y_range[1]) - log_yc
            for p, (t0, t1, state, error, coef) in enumerate(pieces):
                if state != _OK:
                    continue
                t = _map(x_t, t0, t1)
                keep = width * t * t >= math.log1p(guard)
                if not keep.any():
                    continue
                exact = _counted(self, math.exp(a), math.exp(b), np.exp(log_yc + width * t[keep] ** 2), self.check_rtol)
                got = np.polynomial.chebyshev.chebval3d(np.full(keep.sum(), x), np.full(keep.sum(), y), x_t[keep], coef)
                err = SAFETY * float(np.max(np.abs(got - exact)))
                if err > self.tol:
                    failing.add(p)
                pieces[p] = (t0, t1, state, max(error, err), coef)
        return sorted(failing)

    @property
    def a_nodes(self):
        return self._nodes[0]

    @property
    def b_nodes(self):
        return self._nodes[1]


def _root_grid(domain):
    (c1_lo, c1_hi), (c2_lo, c2_hi) = domain["hertz_damping"], domain["adhesion_damping"]
    na = max(1, round(math.log10(c1_hi / c1_lo) * CELLS_PER_DECADE))
    nb = max(1, round(math.log10(c2_hi / c2_lo) * CELLS_PER_DECADE))
    return math.log(c1_lo), math.log(c1_hi), math.log(c2_lo), math.log(c2_hi), na, nb


def build_ring_emulator(tol: float = DEFAULT_TOLERANCE, domain: dict | None = None) -> RingEmulator:
    """Build the table of the ring law's e_n to the absolute tolerance ``tol`` over ``domain``.

    Parameters
    ----------
    tol : float
        Absolute tolerance on e_n that each accepted piece is checked to (module docstring). [-]
    domain : dict, optional
        The box of the groups, as :data:`DOMAIN` (the default). [-]

    Returns
    -------
    RingEmulator

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (27)-(32); Trefethen (2013), Approximation Theory and
    Approximation Practice, SIAM.

    Examples
    --------
    A small box builds in seconds; its checked error is within the tolerance:

    >>> em = build_ring_emulator(1e-3, EXAMPLE_DOMAIN)
    >>> em.max_check_error <= 1e-3, em.arrays["cell_state"].tolist()
    (True, [0])
    """
    domain = dict(DOMAIN if domain is None else domain)
    b = _Builder(tol, domain)
    a0, a1, b0, b1, na, nb = _root_grid(domain)
    wa, wb = (a1 - a0) / na, (b1 - b0) / nb
    with engine_threads(1):  # small batches: a second thread costs more than it gains (solvers.engine_threads)
        roots = [b.node((a0 + i * wa, a0 + (i + 1) * wa, b0 + j * wb, b0 + (j + 1) * wb), 0)
                 for i in range(na) for j in range(nb)]
    return RingEmulator(float(tol), domain, b.n_solves, b.max_check_error, _arrays(b, roots, domain))


def _arrays(b, roots, domain):
    """The builder's cells and pieces as the flat arrays of the compiled evaluation."""
    a0, a1, b0, b1, na, nb = _root_grid(domain)
    pieces = [p for c in b.cells for p in c["pieces"]]
    counts = np.array([len(c["pieces"]) for c in b.cells], dtype=np.int64)
    shape = (DEGREE_AB + 1, DEGREE_AB + 1, DEGREE_T + 1)
    return {
        "box": np.array([a0, a1, b0, b1, na, nb, *domain["incident_speed"]], dtype=float),
        "roots": np.array(roots, dtype=np.int64),
        "children": np.array(b.children, dtype=np.int64).reshape(-1, 4),
        "leaf": np.array(b.leaf, dtype=np.int64),
        "cell_state": np.array([c["state"] for c in b.cells], dtype=np.int64),
        "guard": np.array([c["guard"] for c in b.cells], dtype=float),
        "surface": np.array([c["surface"] for c in b.cells], dtype=float).reshape(-1, DEGREE_SURFACE + 1, DEGREE_SURFACE + 1),
        "piece_cell": np.repeat(np.arange(len(b.cells)), counts),
        "piece_start": np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64),
        "piece_count": counts,
        "piece_t": np.array([p[:2] for p in pieces], dtype=float).reshape(-1, 2),
        "piece_state": np.array([p[2] for p in pieces], dtype=np.int64),
        "piece_error": np.array([p[3] for p in pieces], dtype=float),
        "piece_coef": np.array([p[4] for p in pieces], dtype=float).reshape(-1, *shape),
    }


# --------------------------------------------------------------------------- the cache
def cache_dir() -> Path:
    """Where built tables are kept: ``$MICROIMPACT_CACHE``, else ``$XDG_CACHE_HOME/microimpact``, else
    ``~/.cache/microimpact`` (outside the install tree, as numba's cache).

    Examples
    --------
    >>> import os
    >>> os.environ["MICROIMPACT_CACHE"] = "/tmp/mi-cache"
    >>> str(cache_dir())
    '/tmp/mi-cache'
    >>> del os.environ["MICROIMPACT_CACHE"]
    """
    if os.environ.get("MICROIMPACT_CACHE"):
        return Path(os.environ["MICROIMPACT_CACHE"]).absolute()
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "microimpact"


_SOURCES = ("model/law.py", "model/contact.py", "model/reduction.py", "solvers/engine.py", "solvers/emulator.py")
_SETTINGS = (DEGREE_SURFACE, DEGREE_AB, DEGREE_T, CELLS_PER_DECADE, MAX_DEPTH, CELL_CHECKS, T_CHECKS, T_CHECK_NODES, INITIAL_PIECES,
             MIN_PIECE, SCAN, SECTIONS, CAPTURE_WIDTH, SAFETY, NODE_RTOL, NODE_RTOL_FLOOR, NODE_RTOL_CEILING, CAPTURE_RTOL,
             CHECK_RTOL_FACTOR, NEAR_CAPTURE_T, _LAYOUT)


def _table_name(tol, domain) -> str:
    """The table's file name: its tolerance, and a hash of the domain, the settings and the physics' source."""
    root = Path(__file__).resolve().parent.parent
    h = hashlib.sha256(repr((float(tol), sorted(domain.items()), _SETTINGS)).encode())
    for name in _SOURCES:
        h.update((root / name).read_bytes())
    return f"ring-{tol:.0e}-{h.hexdigest()[:16]}.npz"


def _cache_path(tol, domain) -> Path:
    return cache_dir() / _table_name(tol, domain)


def shipped_dir() -> Path:
    """The package's directory of shipped tables (read only; :data:`SHIPPED`).

    Examples
    --------
    >>> shipped_dir().parts[-2:]
    ('data', 'emulator')
    """
    return Path(str(files("microimpact") / "data" / "emulator"))


def ship_tables(dest: str | os.PathLike | None = None) -> list[Path]:
    """Write the tables of :data:`SHIPPED` to ``dest`` (default :func:`shipped_dir`), removing stale ones.

    Run after a change of the law, the engine or this module (the test of the shipped tables says
    when): ``python -c "from microimpact.solvers.emulator import ship_tables; ship_tables()"`` in a
    clone with an editable install. Each table comes from :func:`ring_emulator` (the cache, or built).

    Returns
    -------
    list of pathlib.Path
        The tables written.
    """
    dest = shipped_dir() if dest is None else Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    keep = {_table_name(tol, dict(domain)) for tol, domain in SHIPPED}
    for old in dest.glob("ring-*.npz"):
        if old.name not in keep:
            old.unlink()
    written = []
    for tol, domain in SHIPPED:
        path = dest / _table_name(tol, dict(domain))
        _save(ring_emulator(tol, domain), path)
        written.append(path)
    return written


def _save(em: RingEmulator, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(f".{os.getpid()}.tmp.npz")
    np.savez(tmp, tolerance=em.tolerance, n_solves=em.n_solves, max_check_error=em.max_check_error, **em.arrays)
    os.replace(tmp, path)  # whole or not at all: a reader never sees half a table


def _load(path: Path, domain) -> RingEmulator:
    with np.load(path) as f:
        arrays = {k: f[k] for k in f.files if k not in ("tolerance", "n_solves", "max_check_error")}
        return RingEmulator(float(f["tolerance"]), dict(domain), int(f["n_solves"]), float(f["max_check_error"]), arrays)


_LOADED: dict = {}


def ring_emulator(tol: float = DEFAULT_TOLERANCE, domain: dict | None = None) -> RingEmulator:
    """The table for ``tol`` over ``domain``: from memory, else shipped (:func:`shipped_dir`), else from
    :func:`cache_dir`, else built and saved there.

    Examples
    --------
    The second call reads it from memory; the file is in the cache directory:

    >>> import os
    >>> os.environ["MICROIMPACT_CACHE"] = "emulator-cache"
    >>> ring_emulator(1e-3, EXAMPLE_DOMAIN) is ring_emulator(1e-3, EXAMPLE_DOMAIN)
    True
    >>> [p.suffix for p in cache_dir().iterdir()]
    ['.npz']
    >>> del os.environ["MICROIMPACT_CACHE"]
    """
    domain = dict(DOMAIN if domain is None else domain)
    name = _table_name(tol, domain)
    if name in _LOADED:
        return _LOADED[name]
    shipped, path = shipped_dir() / name, cache_dir() / name
    if shipped.exists():
        em = _load(shipped, domain)
    elif path.exists():
        em = _load(path, domain)
    else:
        em = build_ring_emulator(tol, domain)
        _save(em, path)
    _LOADED[name] = em
    return em


# --------------------------------------------------------------------------- the entry point
def table_tolerance(tol) -> float:
    """The table used for the e_n tolerance ``tol``: the power of ten at or below it (a few tables
    serve every tol). [-]

    Examples
    --------
    >>> table_tolerance(3e-6)
    1e-06
    """
    t = float(tol)
    if not (math.isfinite(t) and 0.0 < t < 1.0):
        raise ValueError(f"tol must be a finite number in (0, 1), got {tol!r}")
    return 10.0 ** math.floor(math.log10(t) + 1e-12)


def _as_rows(contacts, speeds):
    """(list of contacts, speeds as an (N, M) array, output shape) from the accepted forms."""
    v = np.asarray(speeds, dtype=float)
    if isinstance(contacts, Contact):
        return [contacts], v.reshape(1, -1), v.shape
    contacts = list(contacts)
    if not contacts or not all(isinstance(c, Contact) for c in contacts):
        raise TypeError("contacts must be a Contact or a non-empty sequence of Contacts")
    if v.ndim == 0 or v.shape[0] != len(contacts):
        raise ValueError(f"speeds must have the contacts' number ({len(contacts)}) along its first axis, "
                         f"got shape {v.shape}")
    return contacts, v.reshape(len(contacts), -1), v.shape


def restitution(contacts, speeds, *, tol: float = DEFAULT_TOLERANCE, domain: dict | None = None) -> Restitution:
    """e_n and capture of normal impacts of many contacts: the table where it meets ``tol``, the solver elsewhere.

    Parameters
    ----------
    contacts : Contact or sequence of Contact
        One contact for all ``speeds``, or N contacts, row i of ``speeds`` belonging to contact i.
        Contacts of another law than the ring law (:func:`microimpact.model.reduction.law_of`) are
        solved throughout.
    speeds : array_like
        Incident normal speeds, > 0; with N contacts, shape (N,) or (N, M). [m/s]
    tol : float
        Absolute tolerance on e_n: the table of the power of ten at or below it is used (built and
        cached on first use, :func:`ring_emulator`), and impacts whose estimate exceeds ``tol`` are
        solved at ``rtol = tol / 100``. [-]
    domain : dict, optional
        The table's box of groups (default :data:`DOMAIN`). [-]

    Returns
    -------
    Restitution
        Arrays of the shape of ``speeds``.

    References
    ----------
    Cheng, Brach & Dunn (2002), Eqs. (21) and (27)-(32).

    Examples
    --------
    The paper's microsphere with less damping; at 30 m/s its groups leave the example's box
    (C1 = 1.5e-3 y0^(-1/5)), and that impact is solved:

    >>> import os
    >>> from microimpact.model.parameters import TABLE1_ROW2
    >>> c = TABLE1_ROW2.with_(zeta_hertz=0.2, zeta_adhesion=20.0)
    >>> os.environ["MICROIMPACT_CACHE"] = "emulator-cache"
    >>> r = restitution(c, [0.5, 3.0, 30.0], tol=1e-3, domain=EXAMPLE_DOMAIN)
    >>> r.captured.tolist(), r.solved.tolist(), r.e_n.round(3).tolist()
    ([True, False, False], [False, False, True], [0.0, 0.706, 0.816])
    >>> del os.environ["MICROIMPACT_CACHE"]
    """
    rows, v, shape = _as_rows(contacts, speeds)
    if not np.all(np.isfinite(v) & (v > 0.0)):
        raise ValueError("speeds must be finite numbers > 0")
    table_tol = table_tolerance(tol)
    rings = [reduction.law_of(c) == "ring" for c in rows]
    table = ring_emulator(table_tol, domain) if any(rings) else None
    e, captured = np.zeros(v.shape), np.zeros(v.shape, dtype=bool)
    solve = np.ones(v.shape, dtype=bool)
    ring = np.flatnonzero(rings)
    if ring.size:  # the groups of all contacts and the table, each in one call
        y0, c1, c2 = reduction.ring_groups([rows[i] for i in ring], v[ring])
        e[ring], captured[ring], solve[ring] = table.evaluate(y0, c1, c2, tol)
    with engine_threads(1):
        for i in np.flatnonzero(solve.any(axis=1)):
            e[i, solve[i]] = fallback_restitution(rows[i], v[i, solve[i]], float(tol))
    captured[solve] = e[solve] == 0.0
    return Restitution(e.reshape(shape), captured.reshape(shape), solve.reshape(shape), float(tol))


def fallback_restitution(contact, speeds, tol: float) -> np.ndarray:
    """e_n of one contact's impacts by the solver, to the absolute tolerance ``tol``: where the table
    leaves an impact to the solver.

    The solves run at ``rtol = FALLBACK_RTOL tol``; those that barely rebound (e_n <
    :data:`NEAR_CAPTURE_E`, where the solve's error is ~1.2 rtol / e_n) again at ``tol e_n / 12``.

    Parameters
    ----------
    contact : Contact
    speeds : array_like
        Incident normal speeds, > 0. [m/s]
    tol : float
        Absolute tolerance on e_n. [-]

    Returns
    -------
    numpy.ndarray
        e_n of each speed, 0 where captured. [-]

    Examples
    --------
    >>> from microimpact.model.parameters import TABLE1_ROW2
    >>> fallback_restitution(TABLE1_ROW2, [0.5, 3.0], 1e-6).round(4).tolist()
    [0.0, 0.5866]
    """
    rtol = max(tol * FALLBACK_RTOL, NODE_RTOL_FLOOR)
    e = np.array(normal_restitution(contact, speeds, rtol=rtol), dtype=float)
    near = (e > 0.0) & (e < NEAR_CAPTURE_E)
    if near.any():
        tight = max(tol * float(e[near].min()) / 12.0, MIN_RTOL * 1.01)
        if tight < rtol:
            e[near] = normal_restitution(contact, speeds[near], rtol=tight)
    return e
