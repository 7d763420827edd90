"""The posterior's model e_n of many rows as one certified Chebyshev curve in speed per walker and radius.

Why
---
For one parameter set (a walker) and one radius the ring groups of Eqs. (28), (31)-(32) move
along one curve as the normal speed v changes: y0 = v T / X, C1 = zeta_H u / (D v^(1/5)) and
C2 = zeta_A u / (D v^(1/5)) (:func:`microimpact.model.reduction.ring_groups`). So the model e_n of
every row of that radius is one smooth function e(v) of the speed above the capture speed v_c,
and a posterior over N rows need not evaluate the emulator N times per walker: an interpolant of
e(v) from a few dozen evaluations holds them all, and the normal likelihood's sum of squares of
those rows follows from moments of the rows computed once.

Method
------
* **Coordinate.** e(v) rises like (v - v_c)^(1/2) from capture: in z = ln(v - v_p), with the
  pole v_p the capture velocity of the least-squares fit, that root is exp(z / 2), entire; a walker
  whose v_c differs from v_p by Delta has its singularity at z = ln|Delta| (+ i pi), far from rows
  with v - v_p >> |Delta|. Rows below (1 + :data:`NEAR_CAPTURE`) v_p stay with the per-row model.
* **Pieces.** [z_min, z_max] of a radius's rows is cut into pieces, halved at set-up (at the fit's
  values) until each meets :data:`SETUP_MARGIN` of the tolerance, at most :data:`MAX_PIECES`; a
  radius that does not, or has fewer than :data:`MIN_ROWS` rows, stays with the per-row model.
* **Interpolant and its error.** On each piece the per-row model (the emulator, ``evaluate``) at
  the 2n + 1 Chebyshev-Lobatto points (n = :data:`HALF_DEGREE`) gives the degree-2n interpolant
  p_2n (Trefethen 2013, ch. 2-3). The even points are the Lobatto points of degree n: the
  interpolant p_n through them, compared with the model at the n odd points (between p_n's
  nodes, where its error is largest), gives the estimate
  eps = :data:`SAFETY` max_odd |p_n - e| (as the table estimates its own pieces). p_2n, the more
  accurate of the two, is used, with the estimate of p_n: a nested, conservative estimate (as
  Gauss-Kronrod quadrature reports its lower rule's error). Every walker's curves are checked at
  every evaluation: a (walker, radius) with a piece whose eps exceeds ``tol``, or a node that is
  captured or not finite, takes the per-row model for all its rows.
* **Moments.** With w_i = 1 / sigma_i^2 and the basis B_ik = T_k(x_i) of a piece, the reference
  residuals r_i = e_i - (B c_ref)_i at the fit's coefficients c_ref and
  G = B^T W B, b = B^T W r, S = r^T W r (computed once), a walker's coefficients c give
  sum_i w_i (e_model,i - e_i)^2 = d^T G d - 2 d^T b + S,  d = c - c_ref      (1)
  in O(n^2) per piece, whatever the rows; the reference keeps the cancellation in (1) at the size
  of the chi-square, not of sum w e^2. A non-quadratic density (Student-t) takes B c per row
  (:meth:`SpeedCurves.values`): still O(rows), but a matrix product instead of table lookups.

Error: each model e_n of a checked curve is within eps <= ``tol`` of the per-row model, so the
sum of squares of a radius moves by at most 2 eps sqrt(W chi2) + eps^2 W (Cauchy-Schwarz, W = sum w)
and the log-likelihood by half that.

References
----------
Trefethen, L. N. (2013), Approximation Theory and Approximation Practice, SIAM, ch. 2-3, 8.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["SpeedCurves", "HALF_DEGREE", "SAFETY", "TOLERANCE_FACTOR", "NEAR_CAPTURE", "MIN_ROWS", "MAX_PIECES",
           "SETUP_MARGIN", "chebyshev_matrices", "certified_curve"]

#: n of the nested pair: p_2n through 2n + 1 Lobatto points, p_n through the even ones
HALF_DEGREE = 12
#: factor from the largest check difference to the error estimate (the emulator's own)
SAFETY = 2.0
#: the curves' tolerance against the per-row model, relative to the likelihood's e_n tolerance:
#: the model of a curve row is within (1 + TOLERANCE_FACTOR) tol of the solver
TOLERANCE_FACTOR = 0.05
#: rows below (1 + NEAR_CAPTURE) times the fit's capture velocity keep the per-row model (e_n's root)
NEAR_CAPTURE = 0.02
#: fewest rows of a radius worth a curve: its nodes cost 2n + 1 evaluations per piece and walker
MIN_ROWS = 400
#: most pieces per radius
MAX_PIECES = 16
#: set-up pieces meet this fraction of the tolerance at the fit's values, so that walkers around it pass
SETUP_MARGIN = 0.25


def chebyshev_matrices(n: int):
    """(x, M, D) of the nested pair on [-1, 1]: x the 2n + 1 Lobatto points (descending),
    M (2n+1, 2n+1) their values -> the coefficients of p_2n (the DCT-I: c_k = (2 / N) sum''_j
    f_j cos(k j pi / N), the first and last halved), D (n, 2n+1) their values -> p_n (through the
    even points) minus the value at each odd point.

    Examples
    --------
    >>> x, M, D = chebyshev_matrices(4)
    >>> f = np.exp(x)
    >>> bool(np.allclose(np.polynomial.chebyshev.chebval(0.3, M @ f), np.exp(0.3), atol=1e-6)), D.shape
    (True, (4, 9))
    """
    def dct(m):
        j = np.arange(m + 1)
        h = np.where((j == 0) | (j == m), 0.5, 1.0)
        return (2.0 / m) * np.cos(np.pi * np.outer(j, j) / m) * h[None, :] * h[:, None]
    x = np.cos(np.pi * np.arange(2 * n + 1) / (2 * n))
    coarse = dct(n)
    odd = x[1::2]
    D = np.zeros((n, 2 * n + 1))
    D[:, 0::2] = np.polynomial.chebyshev.chebvander(odd, n) @ coarse
    D[np.arange(n), 2 * np.arange(n) + 1] -= 1.0
    return x, dct(2 * n), D


class SpeedCurves:
    """The Chebyshev curves of every radius of a likelihood's plain rows (module docstring).

    Parameters
    ----------
    radii : sequence of float
        The radii of the rows. [m]
    rows : sequence of ndarray of int
        Per radius, the indices of its rows in the row arrays.
    speed, e, sigma : ndarray
        The rows' normal speeds [m/s], measured e_n [-] and standard deviations [-].
    poles : sequence of float
        Per radius, the fit's capture velocity v_p. [m/s]
    groups : callable
        ``groups(i, speeds)`` -> (y0, C1 / zeta_H) at the reference w_A of radius i, shape (n,).
    evaluate : callable
        ``evaluate(zh, za, y0, per)`` -> the per-row model e_n (K, n) of K parameter sets at the
        groups (K, n).
    reference : tuple of float
        (zeta_H, zeta_A) of the fit: where the pieces are designed and c_ref is taken.
    tol : float
        The curves' absolute e_n tolerance against ``evaluate``. [-]
    """

    def __init__(self, radii, rows, speed, e, sigma, poles, groups, evaluate, reference, tol):
        self.tol, self.evaluate = float(tol), evaluate
        self.x, self.M, self.D = chebyshev_matrices(HALF_DEGREE)
        self.radius_index, self.rows, self.pieces = [], [], []  # per curve: radius, rows, piece bounds
        self.y_ref, self.per_ref = [], []  # per curve: the nodes' groups (pieces x nodes)
        for i, (idx, pole) in enumerate(zip(rows, poles)):
            idx = np.asarray(idx)
            keep = idx[speed[idx] >= (1.0 + NEAR_CAPTURE) * pole] if math.isfinite(pole) and pole >= 0 else idx[:0]
            if keep.size < MIN_ROWS:
                continue
            z = np.log(speed[keep] - pole)
            bounds = self._design(i, pole, float(z.min()), float(z.max()), groups, reference)
            if bounds is None:
                continue
            y, per = self._node_groups(i, pole, bounds, groups)
            self.radius_index.append(i)
            self.rows.append(keep)
            self.pieces.append(bounds)
            self.y_ref.append(y)
            self.per_ref.append(per)
        self.curve_rows = np.concatenate(self.rows) if self.rows else np.zeros(0, dtype=int)
        ends = np.cumsum([b.shape[0] for b in self.pieces], dtype=int)
        self.piece_of_curve = [np.arange(end - b.shape[0], end) for end, b in zip(ends, self.pieces)]
        self._moments(speed, e, sigma, poles, reference)

    def _node_groups(self, i, pole, bounds, groups):
        """The groups (pieces, 2n + 1) at the Lobatto nodes of each piece of ``bounds`` (pieces, 2)."""
        z = bounds[:, :1] + (bounds[:, 1:] - bounds[:, :1]) * (self.x[None, :] + 1.0) / 2.0
        y, per = groups(i, (pole + np.exp(z)).ravel())
        return y.reshape(z.shape), per.reshape(z.shape)

    def _design(self, i, pole, z_lo, z_hi, groups, reference):
        """Piece bounds (pieces, 2) in z meeting SETUP_MARGIN tol at the fit's values, or None."""
        bounds = np.array([[z_lo, z_hi]])
        zh, za = (np.array([float(v)]) for v in reference)
        while True:
            y, per = self._node_groups(i, pole, bounds, groups)
            values = self.evaluate(zh, za, y.reshape(1, -1), per.reshape(1, -1)).reshape(y.shape)
            estimate = SAFETY * np.abs(values @ self.D.T).max(axis=1)
            bad = ~(np.isfinite(estimate) & (estimate <= SETUP_MARGIN * self.tol) & np.all(values > 0, axis=1))
            if not bad.any():
                return bounds
            if bounds.shape[0] + int(bad.sum()) > MAX_PIECES:
                return None
            mid = bounds.mean(axis=1)
            split = [[[a, m], [m, b]] if f else [[a, b]] for (a, b), m, f in zip(bounds, mid, bad)]
            bounds = np.array([piece for s in split for piece in s])

    def _moments(self, speed, e, sigma, poles, reference):
        """Per piece the basis of its rows and G, b, S of Eq. (1) about the fit's coefficients."""
        self.piece_rows, self.basis, self.G, self.b, self.S = [], [], [], [], []
        self.c_ref = self.coefficients(*(np.array([float(v)]) for v in reference))[0][0] if self.rows else None
        k = 0
        for c, (keep, bounds) in enumerate(zip(self.rows, self.pieces)):
            z = np.log(speed[keep] - poles[self.radius_index[c]])
            which = np.clip(np.searchsorted(bounds[1:, 0], z, side="right"), 0, bounds.shape[0] - 1)
            for p, (a, bb) in enumerate(bounds):
                sel = keep[which == p]
                x = np.clip((2.0 * np.log(speed[sel] - poles[self.radius_index[c]]) - a - bb) / (bb - a), -1.0, 1.0)
                basis = np.polynomial.chebyshev.chebvander(x, 2 * HALF_DEGREE)
                w = 1.0 / sigma[sel] ** 2
                r = e[sel] - basis @ self.c_ref[k]
                self.piece_rows.append(sel)
                self.basis.append(basis)
                self.G.append(basis.T @ (w[:, None] * basis))
                self.b.append(basis.T @ (w * r))
                self.S.append(float(np.sum(w * r * r)))
                k += 1
        if self.rows:
            self.G, self.b, self.S = np.array(self.G), np.array(self.b), np.array(self.S)

    @property
    def n_curves(self) -> int:
        """How many radii have a curve."""
        return len(self.rows)

    def coefficients(self, zeta_hertz, zeta_adhesion, scale=None):
        """(c, ok): the coefficients of p_2n of every piece for K parameter sets, shape
        (K, pieces, 2n + 1), and whether each walker's curve of each radius passes its check,
        (K, curves). ``scale``: the w_A ratio s of each set (K, 1) (groups by their powers of w_A,
        Eq. (7)); None: the reference w_A."""
        y = np.concatenate(self.y_ref)
        per = np.concatenate(self.per_ref)
        k = zeta_hertz.size
        y0, pr = np.broadcast_to(y.ravel(), (k, y.size)), np.broadcast_to(per.ravel(), (k, per.size))
        if scale is not None:
            y0, pr = y0 * scale ** (-5.0 / 6.0), pr * scale ** (5.0 / 6.0)
        values = self.evaluate(zeta_hertz, zeta_adhesion, np.ascontiguousarray(y0), np.ascontiguousarray(pr))
        values = values.reshape(k, y.shape[0], y.shape[1])
        estimate = SAFETY * np.abs(values @ self.D.T).max(axis=2)
        good = np.isfinite(estimate) & (estimate <= self.tol) & np.all(values > 0.0, axis=2)
        ok = np.stack([good[:, idx].all(axis=1) for idx in self.piece_of_curve], axis=1)
        return values @ self.M.T, ok

    def sum_of_squares(self, c) -> np.ndarray:
        """sum_i w_i (e_model,i - e_i)^2 over each curve's rows, Eq. (1), shape (K, curves). [-]"""
        d = c - self.c_ref[None]
        per_piece = (np.einsum("kpm,pmn,kpn->kp", d, self.G, d) - 2.0 * np.einsum("kpm,pm->kp", d, self.b)
                     + self.S[None, :])
        return np.stack([per_piece[:, idx].sum(axis=1) for idx in self.piece_of_curve], axis=1)

    def values(self, c):
        """[(rows, e_model (K, rows))] per curve: the interpolant at the rows (for a density that is
        not quadratic in the residual). [-]"""
        out = []
        for idx in self.piece_of_curve:
            rows = np.concatenate([self.piece_rows[p] for p in idx])
            vals = np.concatenate([c[:, p, :] @ self.basis[p].T for p in idx], axis=1)
            out.append((rows, vals))
        return out


def certified_curve(evaluate, z, tol):
    """A smooth function at many points ``z`` from a few evaluations: piecewise p_2n, checked.

    The nested pair of the module docstring on pieces of [min z, max z], without a fit to design
    them: a piece whose estimate eps exceeds ``tol``, or with a node not finite or not > 0 (capture:
    e_n's root is not smooth) unless all its nodes are 0 (wholly captured), is halved while the
    pieces number at most :data:`MAX_PIECES`; the points of a piece that still fails are reported
    as not certified, for the caller's own solve.

    Parameters
    ----------
    evaluate : callable
        ``evaluate(z_nodes)`` -> the function at the nodes (1-D array in, same shape out).
    z : ndarray
        The points, 1-D, finite.
    tol : float
        Absolute tolerance of the certified points against ``evaluate``.

    Returns
    -------
    values : ndarray
        p_2n of each point's piece at the point (meaningful where ``ok``).
    ok : ndarray of bool
        Whether the point's piece passed its check (eps <= tol).

    Examples
    --------
    >>> z = np.linspace(0.0, 3.0, 1000)
    >>> v, ok = certified_curve(lambda t: np.exp(t / 2.0), z, 1e-10)
    >>> bool(ok.all()), bool(np.abs(v - np.exp(z / 2.0)).max() < 1e-10)
    (True, True)
    """
    x, M, D = chebyshev_matrices(HALF_DEGREE)
    todo, done = [(float(z.min()), float(z.max()))], []  # done: (a, b, values, passed)
    while todo:
        bounds = np.array(todo)
        nodes = bounds[:, :1] + (bounds[:, 1:] - bounds[:, :1]) * (x[None, :] + 1.0) / 2.0
        values = np.asarray(evaluate(nodes.ravel()), dtype=float).reshape(nodes.shape)
        estimate = SAFETY * np.abs(values @ D.T).max(axis=1)
        # all nodes 0: the piece lies below the capture speed (capture holds from v = 0 up to v_c),
        # where e_n = 0 exactly, as p_2n of zeros is
        good = np.isfinite(estimate) & (estimate <= tol) & np.all(values > 0.0, axis=1)
        good |= np.all(values == 0.0, axis=1)
        can_split = len(done) + len(todo) + int((~good).sum()) <= MAX_PIECES
        todo_next = []
        for (a, b), v, g in zip(todo, values, good):
            if g or not can_split or b <= a:
                done.append((a, b, v, bool(g)))
            else:
                m = 0.5 * (a + b)
                todo_next += [(a, m), (m, b)]
        todo = todo_next
    done.sort(key=lambda piece: piece[0])
    lo = np.array([d[0] for d in done])
    which = np.clip(np.searchsorted(lo[1:], z, side="right"), 0, len(done) - 1)
    out = np.empty(z.size)
    ok = np.zeros(z.size, dtype=bool)
    for p, (a, b, v, g) in enumerate(done):
        sel = which == p
        xs = np.clip((2.0 * z[sel] - a - b) / (b - a), -1.0, 1.0) if b > a else np.zeros(int(sel.sum()))
        out[sel] = np.polynomial.chebyshev.chebval(xs, M @ v)
        ok[sel] = g
    return out, ok
