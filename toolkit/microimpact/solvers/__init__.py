"""The solvers: how the model is integrated, behind one interface.

:func:`simulate_impact` (one impact) and :func:`simulate_many` (a broadcast batch) take a
``method=`` switch: ``"engine"`` (compiled 1-D normal solve plus the closed-form tangential map,
:mod:`.engine`) or ``"reference"`` (full 3-D scipy integration, :mod:`.reference`).
"""
