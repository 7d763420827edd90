"""The solvers: how the model is integrated, behind one interface.

:func:`microimpact.simulate_impact` takes a ``method=`` switch and returns one
:class:`~microimpact.model.kinematics.ImpactResult` whatever the method:

- ``"engine"``: compiled 1-D normal solve (Dormand-Prince 5(4) in the Sundman form, :mod:`.engine`)
  plus the closed-form tangential map of :mod:`microimpact.model.tangential`;
- ``"reference"``: the full 3-D equations integrated by scipy (:mod:`.reference`);
- ``"rkg"``: the paper's fixed-step Runge-Kutta-Gill normal solve (:mod:`.rkg`) plus the same map.

:func:`microimpact.simulate_many` (a broadcast batch, :mod:`.impact`) runs the engine only. Every
solver evaluates the contact law of :mod:`microimpact.model.law`; the compiled ones through
:mod:`.compiled_law`, which compiles the law's own functions instead of keeping a copy.
"""

#: The one default relative tolerance of every entry point (API, CLI, pipeline config ``rtol``).
#: At 1e-8 the engine's e_n and impulse ratios are within about 5e-8 of the reference solution
#: (docs/benchmark.md), far below any measurement's uncertainty, at half the cost of 1e-10.
DEFAULT_RTOL = 1e-8

#: The solvers behind simulate_impact(method=...).
METHODS = ("engine", "reference", "rkg")
