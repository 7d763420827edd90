"""The contact law of :mod:`microimpact.model.law`, compiled for the numba solvers.

No formula is written here: each function is the law's own Python function compiled by numba with
``inline="always"``, so it is inlined into its compiled callers (the engine and the
Runge-Kutta-Gill integrator). The scipy reference solver and :mod:`microimpact.dynamics` call the
Python originals. An edit of a law reaches the compiled solvers at their next start: their cache is
keyed by the sources of ``model/`` and ``solvers/`` (:mod:`microimpact._numba`).
"""

from microimpact._numba import njit
from microimpact.model import law


def compiled(func):
    """numba-compiled version of a scalar law function, inlined into compiled callers."""
    return njit(inline="always", cache=True)(func)


#: xi'', Eq. (27), see :func:`microimpact.model.law.nondimensional_acceleration`
nondimensional_acceleration = compiled(law.nondimensional_acceleration)
#: e(s, y), see :func:`microimpact.model.law.nondimensional_energy`
nondimensional_energy = compiled(law.nondimensional_energy)
#: -de/dtau, see :func:`microimpact.model.law.nondimensional_dissipation_rate`
nondimensional_dissipation_rate = compiled(law.nondimensional_dissipation_rate)
