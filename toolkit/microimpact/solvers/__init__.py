"""The solvers: how the model is integrated, behind one interface.

:func:`microimpact.simulate_impact` (one impact) and :func:`microimpact.simulate_many` (a broadcast
batch) take a ``method=`` switch: ``"engine"`` (compiled 1-D normal solve plus the closed-form
tangential map, :mod:`.engine`), ``"reference"`` (full 3-D scipy integration, :mod:`.reference`) or
``"rkg"`` (the paper's fixed-step Runge-Kutta-Gill, :mod:`.rkg`).
"""

#: The one default relative tolerance of every entry point (API, CLI, pipeline config ``rtol``).
#: At 1e-8 the engine's e_n and impulse ratios are within about 5e-8 of the reference solution
#: (docs/benchmark.md), far below any measurement's uncertainty, at half the cost of 1e-10.
DEFAULT_RTOL = 1e-8

#: The solvers behind simulate_impact(method=...).
METHODS = ("engine", "reference", "rkg")
