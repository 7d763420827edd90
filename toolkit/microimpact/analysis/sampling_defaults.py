"""The posterior sampler's defaults, in a module that imports nothing.

:mod:`microimpact.analysis.posterior` uses them and re-exports them; the command line reads them
from here to print them in its help, which must not wait for scipy and xarray to import
(``microimpact --help`` is held to three times the start-up of ``python -c "import numpy"``,
.ci/startup.py).

Examples
--------
>>> from microimpact.analysis import posterior
>>> posterior.DEFAULT_WALKERS == DEFAULT_WALKERS
True
"""

__all__ = ["DEFAULT_WALKERS", "DEFAULT_MAX_STEPS", "DEFAULT_SEED", "DEFAULT_N_DRAWS", "MAX_SEED", "LIKELIHOODS",
           "DEFAULT_NU", "LOSSES", "DEFAULT_LOSS", "METHODS", "DEFAULT_METHOD", "DEFAULT_FIT_METHOD"]

#: walkers of the ensemble (at least 2 x the sampled parameters are needed; 16 suits 2-4)
DEFAULT_WALKERS = 16
#: steps after which an unconverged chain is an error (with the time budget, the chain's budget)
DEFAULT_MAX_STEPS = 20000
#: seed of the start ball and the sampler
DEFAULT_SEED = 2002
#: the largest seed: the posterior file stores it as a CF integer attribute (int32)
MAX_SEED = 2**31 - 1
#: posterior draws pushed through the bands and the flags
DEFAULT_N_DRAWS = 24
#: e_n likelihoods of the posterior: normal, or Student-t (heavy tails, for gross outliers)
LIKELIHOODS = ("normal", "student-t")
#: degrees of freedom of the Student-t likelihood: 4, the value Lange, Little & Taylor (1989,
#: doi:10.1080/01621459.1989.10478852) found to serve across their examples
DEFAULT_NU = 4.0
#: losses of the damping fit (scipy.optimize.least_squares's names; :mod:`microimpact.analysis.fitting`):
#: "linear" is least squares, here because the command line's help names them
LOSSES = ("linear", "soft_l1", "huber")
#: the loss of the damping fit: plain least squares
DEFAULT_LOSS = "linear"
#: how the posterior's likelihood evaluates the model e_n: "emulator" (the ring law's table,
#: :mod:`microimpact.solvers.emulator`, the solver where it falls back) or "solve" (the solver at
#: every evaluation, the reference)
METHODS = ("emulator", "solve")
#: the likelihood's method by default: the emulator, whose table comes with the package
DEFAULT_METHOD = "emulator"
#: how the damping fit evaluates the model e_n (the same two methods; the fit takes the table only
#: for a radius with thousands of rows, :data:`microimpact.analysis.fitting.EMULATOR_MIN_ROWS`)
DEFAULT_FIT_METHOD = "emulator"
