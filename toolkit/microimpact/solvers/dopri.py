"""The one Dormand-Prince 5(4) core of the compiled solvers.

The engine (:mod:`microimpact.solvers.engine`), the coupled tangential solver
(:mod:`microimpact.solvers.coupled`) and the JKR/DMT/Hertz solver
(:mod:`microimpact.solvers.normal_models`) integrate their contact laws with the same explicit
Runge-Kutta pair of Dormand & Prince (1980) [1]_, written here once: the tableau, the step, the error
norm and the step-size control [2]_, the Illinois root finder [3]_ and the cubic Hermite interpolant of
a step.
Each law plugs in a compiled right-hand side here, and its events (which differ by law: separation,
turning point, capture, the change of slip, the rolling stop) into the one driver
(:mod:`microimpact.solvers.driver`), which runs this step.

A law is plugged in by :func:`make_step`, which compiles the step for one right-hand side
``rhs(u, out, args)`` (writes d/dsigma of the state ``u`` into ``out``; ``args``, a tuple, holds
the law's parameters; a tuple rather than ``*args``, because numba cannot inline a function called
with ``*args``). It is a factory rather than a compiled function taking ``rhs`` as an argument
because numba cannot cache a compiled function that receives another one as an argument (it then
recompiles on every start); a closure over ``rhs`` is cached, keyed by the closure's contents.

The scipy reference (:mod:`microimpact.solvers.reference`) and the Runge-Kutta-Gill integrator of
the paper (:mod:`microimpact.solvers.rkg`) do not use this core, on purpose: they are the
independent yardsticks the core is tested against.

References
----------
.. [1] Dormand, J. R. & Prince, P. J. (1980). A family of embedded Runge-Kutta formulae.
   J. Comput. Appl. Math. 6, 19-26.
.. [2] Hairer, E., Norsett, S. P. & Wanner, G. (1993). Solving Ordinary Differential Equations I,
   2nd ed., Springer, Sec. II.4 (step-size control) and II.6 (dense output).
.. [3] Dowell, M. & Jarratt, P. (1971). A modified regula falsi method for computing the root of
   an equation. BIT 11, 168-174 (the Illinois method).
"""

from __future__ import annotations

import math

from microimpact._numba import njit

__all__ = ["make_step", "make_root_on_step", "error_norm", "scaled_error_sum", "grown_step", "shrunk_step",
           "illinois_point", "illinois_update", "hermite"]

# Dormand-Prince 5(4) tableau [1]
A21 = 1.0 / 5.0
A31, A32 = 3.0 / 40.0, 9.0 / 40.0
A41, A42, A43 = 44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0
A51, A52, A53, A54 = 19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0
A61, A62, A63, A64, A65 = 9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0, 49.0 / 176.0, -5103.0 / 18656.0
B1, B3, B4, B5, B6 = 35.0 / 384.0, 500.0 / 1113.0, 125.0 / 192.0, -2187.0 / 6784.0, 11.0 / 84.0
# error coefficients b - b_hat (b2 = e2 = 0)
E1, E3, E4, E5, E6, E7 = 71.0 / 57600.0, -71.0 / 16695.0, 71.0 / 1920.0, -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0

#: step-size control [2]: safety factor, exponent 1/5, and the bounds of the change per step
_SAFETY, _EXPONENT, _MIN_FACTOR, _MAX_FACTOR = 0.9, -0.2, 0.2, 5.0


def make_step(rhs, n):
    """The compiled Dormand-Prince 5(4) step of a contact law.

    Parameters
    ----------
    rhs : numba-compiled function
        ``rhs(u, out, args)``: writes the derivative of the state ``u`` (length n) into ``out``;
        ``args`` is a tuple of the law's parameters.
    n : int
        Number of states (a compile-time constant of the step, so that LLVM unrolls its loops).

    Returns
    -------
    step : numba-compiled function
        ``step(u0, k1, h, args, k, tmp, u1, err)``: one step of length h from u0, whose derivative
        is k1; writes the state u1 at its end, the error estimate err (5th minus embedded 4th
        order), the stages into the rows of k (7, n) and, first same as last, k[6] = f(u1).
        tmp is scratch.

    References
    ----------
    Dormand & Prince (1980), see the module docstring.

    Examples
    --------
    >>> import numpy as np
    >>> from microimpact._numba import njit
    >>> @njit
    ... def decay(u, out, args):
    ...     out[0] = -args[0] * u[0]
    >>> step = make_step(decay, 1)
    >>> u0, k1, u1, err = np.ones(1), np.array([-1.0]), np.zeros(1), np.zeros(1)
    >>> step(u0, k1, 0.1, (1.0,), np.zeros((7, 1)), np.zeros(1), u1, err)
    >>> bool(abs(u1[0] - np.exp(-0.1)) < 1e-8)
    True
    """

    @njit(cache=True)
    def step(u0, k1, h, args, k, tmp, u1, err):
        for i in range(n):
            k[0, i] = k1[i]
        for i in range(n):
            tmp[i] = u0[i] + h * A21 * k[0, i]
        rhs(tmp, k[1], args)
        for i in range(n):
            tmp[i] = u0[i] + h * (A31 * k[0, i] + A32 * k[1, i])
        rhs(tmp, k[2], args)
        for i in range(n):
            tmp[i] = u0[i] + h * (A41 * k[0, i] + A42 * k[1, i] + A43 * k[2, i])
        rhs(tmp, k[3], args)
        for i in range(n):
            tmp[i] = u0[i] + h * (A51 * k[0, i] + A52 * k[1, i] + A53 * k[2, i] + A54 * k[3, i])
        rhs(tmp, k[4], args)
        for i in range(n):
            tmp[i] = u0[i] + h * (A61 * k[0, i] + A62 * k[1, i] + A63 * k[2, i] + A64 * k[3, i] + A65 * k[4, i])
        rhs(tmp, k[5], args)
        for i in range(n):
            u1[i] = u0[i] + h * (B1 * k[0, i] + B3 * k[2, i] + B4 * k[3, i] + B5 * k[4, i] + B6 * k[5, i])
        rhs(u1, k[6], args)
        for i in range(n):
            err[i] = h * (E1 * k[0, i] + E3 * k[2, i] + E4 * k[3, i] + E5 * k[4, i] + E6 * k[5, i] + E7 * k[6, i])

    return step


def make_root_on_step(step, value):
    """The compiled root finder on a step's length, for the step of one law.

    Parameters
    ----------
    step : numba-compiled function
        A step made by :func:`make_step`.
    value : numba-compiled function
        ``value(u, code, vargs)``: the event function ``code`` at the state ``u`` (``vargs``: a tuple
        of its parameters).

    Returns
    -------
    root : numba-compiled function
        ``root(code, target, fa, fb, tol, h, u0, k1, args, vargs, k, tmp, u1, err)``: the step length
        in (0, h] at which ``value`` of the stepped state reaches ``target`` (fa, fb: the value less
        target at the step's ends, of opposite signs), by the Illinois method on the step length,
        re-stepping from u0 at each trial; u1 then holds the state there. Stops where
        |value - target| <= tol or the bracket is below 1e-14 h.

    Notes
    -----
    The step itself, not its interpolant, is solved: a recorded instant (a capture time where the
    energy falls slowly) is then as accurate as the step, where the cubic interpolant was 1e-6 off
    at rtol 1e-9.

    References
    ----------
    Dowell & Jarratt (1971), see the module docstring.

    Examples
    --------
    >>> import numpy as np
    >>> from microimpact._numba import njit
    >>> @njit
    ... def fall(u, out, args):
    ...     out[0], out[1] = u[1], -args[0]
    >>> @njit
    ... def height(u, code, vargs):
    ...     return u[0]
    >>> step = make_step(fall, 2)
    >>> root = make_root_on_step(step, height)
    >>> u0, k1 = np.array([1.0, 0.0]), np.array([0.0, -2.0])
    >>> k, tmp, u1, err = np.zeros((7, 2)), np.zeros(2), np.zeros(2), np.zeros(2)
    >>> step(u0, k1, 2.0, (2.0,), k, tmp, u1, err)
    >>> h = root(0, 0.0, 1.0, u1[0], 0.0, 2.0, u0, k1, (2.0,), (), k, tmp, u1, err)
    >>> round(float(h), 12)  # the fall from 1 m at 2 m/s^2 lasts 1 s
    1.0
    """

    @njit(cache=True)
    def root(code, target, fa, fb, tol, h, u0, k1, args, vargs, k, tmp, u1, err):
        a, b = 0.0, h
        side = 0
        hs = h
        for _ in range(60):
            hs = illinois_point(a, fa, b, fb)
            step(u0, k1, hs, args, k, tmp, u1, err)
            g = value(u1, code, vargs) - target
            if abs(g) <= tol or (b - a) < 1e-14 * h:
                break
            a, fa, b, fb, side = illinois_update(a, fa, b, fb, hs, g, side)
        return hs

    return root


@njit(cache=True, inline="always")
def scaled_error_sum(u0, u1, err, atol, rtol, n):
    """Sum of the squared scaled errors of the first n states of a step u0 -> u1 [2].

    Each error is scaled by atol_i + rtol max(|u0_i|, |u1_i|).

    Examples
    --------
    >>> import numpy as np
    >>> float(scaled_error_sum(np.ones(2), np.ones(2), np.array([1e-6, 0.0]), np.zeros(2), 1e-6, 2))
    1.0
    """
    en = 0.0
    for i in range(n):
        en += (err[i] / (atol[i] + rtol * max(abs(u0[i]), abs(u1[i])))) ** 2
    return en


@njit(cache=True, inline="always")
def error_norm(u0, u1, err, atol, rtol, n):
    """The error norm of a step u0 -> u1 of n states: the root mean square of the scaled errors
    (:func:`scaled_error_sum`); a step is accepted where it is at most 1 [2].

    Examples
    --------
    >>> import numpy as np
    >>> float(error_norm(np.ones(4), np.ones(4), np.array([2e-6, 0.0, 0.0, 0.0]), np.zeros(4), 1e-6, 4))
    1.0
    """
    return math.sqrt(scaled_error_sum(u0, u1, err, atol, rtol, n) / n)


@njit(cache=True, inline="always")
def grown_step(h, norm):
    """The next step after an accepted step of length h and error norm ``norm``:
    h * min(5, max(0.2, 0.9 norm^(-1/5))), and 5 h at a zero norm [2].

    Examples
    --------
    >>> grown_step(1.0, 0.0), round(grown_step(1.0, 1.0), 12)
    (5.0, 0.9)
    """
    if norm == 0.0:
        return h * _MAX_FACTOR
    return h * min(_MAX_FACTOR, max(_MIN_FACTOR, _SAFETY * norm ** _EXPONENT))


@njit(cache=True, inline="always")
def shrunk_step(h, norm):
    """The step to retry after a step of length h was rejected with error norm ``norm`` (> 1, or
    NaN where a trial step overflowed): h * max(0.2, 0.9 norm^(-1/5)), and 0.2 h at a NaN [2].

    Examples
    --------
    >>> shrunk_step(1.0, float("nan")), shrunk_step(1.0, 1e9)
    (0.2, 0.2)
    """
    if not norm == norm:
        return h * _MIN_FACTOR
    return h * max(_MIN_FACTOR, _SAFETY * norm ** _EXPONENT)


@njit(cache=True, inline="always")
def illinois_point(a, fa, b, fb):
    """The regula falsi point of a bracket [a, b] with f(a) = fa, f(b) = fb of opposite signs (its
    midpoint where rounding puts that point outside) [3].

    Examples
    --------
    >>> illinois_point(0.0, -1.0, 2.0, 1.0)
    1.0
    """
    x = (a * fb - b * fa) / (fb - fa)
    return x if a < x < b else 0.5 * (a + b)


@njit(cache=True, inline="always")
def illinois_update(a, fa, b, fb, x, fx, side):
    """The bracket after f(x) = fx, keeping the sign change; an end kept twice in a row has its
    value halved (the Illinois method [3]: superlinear where plain regula falsi stalls at one end).

    ``side`` (0 at the start) records which end moved last; returns (a, fa, b, fb, side).

    Examples
    --------
    >>> illinois_update(0.0, -1.0, 2.0, 1.0, 1.0, 0.5, 0)
    (0.0, -1.0, 1.0, 0.5, -1)
    """
    if (fx > 0.0) == (fb > 0.0):
        if side == -1:
            fa *= 0.5
        return a, fa, x, fx, -1
    if side == 1:
        fb *= 0.5
    return x, fx, b, fb, 1


@njit(cache=True, inline="always")
def hermite(p0, p1, d0, d1, h, th):
    """The cubic Hermite interpolant of a step of length h (values p0, p1, derivatives d0, d1 at
    its ends) at the fraction th of the step [2].

    Examples
    --------
    >>> hermite(0.0, 1.0, 2.0, 0.0, 1.0, 0.5)  # a parabola 2t - t^2 at t = 1/2
    0.75
    """
    th2 = th * th
    th3 = th2 * th
    return (2.0 * th3 - 3.0 * th2 + 1.0) * p0 + (th3 - 2.0 * th2 + th) * h * d0 + (3.0 * th2 - 2.0 * th3) * p1 + (th3 - th2) * h * d1
