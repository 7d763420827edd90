"""The solvers: how the model is integrated, behind one interface.

:func:`microimpact.simulate_impact` takes a ``method=`` switch and returns one
:class:`~microimpact.model.kinematics.ImpactResult` whatever the method:

- ``"engine"``: compiled 1-D normal solve (Dormand-Prince 5(4) in the Sundman form, :mod:`.engine`;
  for the JKR and DMT normal models :mod:`.normal_models`) plus the closed-form tangential map of
  :mod:`microimpact.model.tangential`; a contact that selects tangential compliance or
  adhesion-aware friction runs the compiled coupled solver (:mod:`.coupled`) instead, so the
  paper's model pays nothing for them;
- ``"reference"``: the full 3-D equations integrated by scipy (:mod:`.reference`); for the JKR and
  DMT normal models their normal law integrated by scipy in physical time
  (:func:`.normal_models.solve_normal_reference`) plus the same tangential map;
- ``"rkg"``: the paper's fixed-step Runge-Kutta-Gill normal solve (:mod:`.rkg`) plus the same map.

:func:`microimpact.simulate_many` (a broadcast batch, :mod:`.impact`) runs the engine only. Beneath them
every solve of one normal impact returns one :class:`~microimpact.solvers.solution.NormalSolution`, which
says why it stopped, and every batch of solves one :class:`~microimpact.solvers.solution.SolutionBatch`
(:mod:`.solution`). Every
solver evaluates the contact law of :mod:`microimpact.model.law`; the compiled ones through
:mod:`.compiled_law`, which compiles the law's own functions instead of keeping a copy.
"""

import contextlib
import math
import numbers
import sys

# the time budgets of every long computation; solvers are where most of them are spent and checked
from microimpact._runtime.budget import Deadline, TimeBudgetExceeded, check_time_budget  # noqa: F401
from microimpact.model import laws

#: The one default relative tolerance of every entry point (API, CLI, pipeline config ``rtol``).
#: At 1e-8 the engine's e_n and impulse ratios are within about 5e-8 of the reference solution
#: (docs/benchmark.md), far below any measurement's uncertainty, at half the cost of 1e-10.
DEFAULT_RTOL = 1e-8
#: The smallest relative tolerance accepted: 100 machine epsilons, as scipy's solve_ivp (below it no
#: double-precision integration can meet the tolerance, and the engine ends at its step limit).
MIN_RTOL = 100.0 * sys.float_info.epsilon


def check_rtol(rtol) -> float:
    """``rtol`` as a float if the solvers can meet it: finite, in [:data:`MIN_RTOL`, 1); else a
    TypeError / ValueError saying what is accepted. The CLI's ``--rtol`` and the pipeline's config
    key ``rtol`` are checked here too, so all three accept the same values.

    Examples
    --------
    >>> check_rtol(1e-8)
    1e-08
    >>> check_rtol(1e-300)
    Traceback (most recent call last):
    ...
    ValueError: rtol must be >= 2.22e-14 (100 machine epsilons; a smaller tolerance cannot be met in double precision), got 1e-300
    """
    if isinstance(rtol, bool) or not isinstance(rtol, numbers.Real):
        raise TypeError(f"rtol must be a real number, got {type(rtol).__name__} {rtol!r}")
    if not (math.isfinite(rtol) and 0.0 < rtol < 1.0):
        raise ValueError(f"rtol must be finite and lie in (0, 1), got {rtol!r}")
    if rtol < MIN_RTOL:
        raise ValueError(f"rtol must be >= {MIN_RTOL:.3g} (100 machine epsilons; a smaller tolerance cannot be "
                         f"met in double precision), got {rtol!r}")
    return float(rtol)


class SolverError(RuntimeError):
    """A solver could not finish an impact: a caller's step limit, a step-size underflow, no outcome
    within the reference solver's limits. The base of :class:`~microimpact.solvers.engine.EngineError`,
    :class:`~microimpact.solvers.coupled.CoupledError` and
    :class:`~microimpact.solvers.reference.ReferenceSolverError`, so that one ``except`` catches a
    failure of any solver."""


class UndeterminedOutcomeWarning(UserWarning):
    """A result the solver returns but cannot determine to its tolerance: the message says which
    values, how many impacts and the error estimate; each :class:`~microimpact.model.kinematics.ImpactResult`
    says it in ``not_determined``. Issued for captured spheres held by friction with rolling
    resistance whose final rolling the rolling torque's reversals leave undetermined
    (:func:`microimpact.solvers.coupled._held_rolling_error`).

    Examples
    --------
    Turn it into an error where an undetermined number must not pass:

    >>> import warnings
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("error", UndeterminedOutcomeWarning)
    ...     issubclass(UndeterminedOutcomeWarning, UserWarning)
    True
    """


class ModelDomainError(ValueError):
    """Valid numbers whose impact leaves the domain of the model: a result in SI units would not be
    representable (e.g. a twist impulse beyond 1.8e308 N m s at a penetration 1e64 m into a 3 um
    sphere, where Hertz contact, x << r, no longer applies). The message says which quantity and
    gives the penetration over the radius."""


@contextlib.contextmanager
def engine_threads(threads: int | None = 1):
    """Run the compiled solvers on ``threads`` threads inside the block (None: unchanged), restored after.

    One thread for the fits and the sampler: they make thousands of small engine calls, for which
    thread start-up and, on a shared machine, waiting for the second thread cost more than the
    second core gains.

    Examples
    --------
    >>> import numba
    >>> with engine_threads(1):
    ...     numba.get_num_threads()
    1
    """
    if threads is None:
        yield
        return
    import numba  # start-up: importing the solvers' package loads no numba

    previous = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        yield
    finally:
        numba.set_num_threads(previous)


#: The solvers behind simulate_impact(method=...).
METHODS = ("engine", "reference", "rkg")

#: What each solver path covers of the selectable sub-models (microimpact.model.contact.SUB_MODELS),
#: derived from the laws' own declarations (microimpact.model.laws, SubModel.methods); a contact that
#: selects anything else is refused by :func:`check_sub_models` with a message that says which
#: method does cover it. The engine runs the paper's model (rigid, net) as one normal solve plus the
#: closed-form map and every other tangential/friction choice with the compiled coupled solver (.coupled).
SUPPORTED_SUB_MODELS: dict[str, dict[str, tuple[str, ...]]] = {m: laws.supported(m) for m in METHODS}
#: solver paths that model rolling resistance (Contact.rolling_friction > 0): the engine's coupled
#: solver (.coupled), with a compliant tangential model (ROLLING_RESISTANCE_TANGENTIAL_MODELS)
ROLLING_RESISTANCE_METHODS: tuple[str, ...] = ("engine",)
#: tangential models with which rolling resistance is integrated (the tangential force is a state)
ROLLING_RESISTANCE_TANGENTIAL_MODELS: tuple[str, ...] = ("mindlin", "mindlin_deresiewicz")


def check_sub_models(contact, method: str) -> None:
    """ValueError unless solver ``method`` covers every sub-model that ``contact`` selects.

    The message names the field, the selection and the methods that do cover it.
    """
    for field, supported in SUPPORTED_SUB_MODELS[method].items():
        choice = getattr(contact, field)
        if choice not in supported:
            others = [m for m, s in SUPPORTED_SUB_MODELS.items() if choice in s[field]]
            hint = f"; use method={others[0]!r}" if others else "; no solver implements it yet"
            raise ValueError(f"{field}={choice!r} is not covered by method={method!r}{hint}")
    if contact.rolling_friction > 0.0 and method not in ROLLING_RESISTANCE_METHODS:
        hint = f"; use method={ROLLING_RESISTANCE_METHODS[0]!r}" if ROLLING_RESISTANCE_METHODS else "; no solver implements it yet"
        raise ValueError(f"rolling_friction={contact.rolling_friction!r} is not covered by method={method!r}{hint}")
    if (contact.rolling_friction > 0.0 and contact.rolling_model == "torque"
            and contact.tangential_model not in ROLLING_RESISTANCE_TANGENTIAL_MODELS):
        raise ValueError(f"rolling_friction={contact.rolling_friction!r} needs a compliant tangential model "
                         f"(tangential_model one of {', '.join(map(repr, ROLLING_RESISTANCE_TANGENTIAL_MODELS))}), "
                         f"got tangential_model={contact.tangential_model!r}")
    # the coupled solver's laws, as the laws declare them (model.laws.SubModel.coupled); LAMMPS's
    # tangential laws run with their own solver and LAMMPS's normal laws (Contact checks)
    refused = laws.coupled_refusal({f: getattr(contact, f) for f in laws.fields()})
    if refused == "damping_model":
        raise ValueError(f"damping_model={contact.damping_model!r} runs with the paper's tangential map only "
                         "(tangential_model='rigid', friction_model='net'): the coupled solver integrates the "
                         f"paper's damping; got tangential_model={contact.tangential_model!r}, "
                         f"friction_model={contact.friction_model!r}")
    if refused == "normal_model":
        raise ValueError(f"normal_model={contact.normal_model!r} runs with the paper's tangential map only "
                         "(tangential_model='rigid', friction_model='net'): the coupled solver of tangential "
                         f"compliance and adhesion-aware friction integrates the ring normal law; got "
                         f"tangential_model={contact.tangential_model!r}, friction_model={contact.friction_model!r}")
