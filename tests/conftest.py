"""Test-suite policy shared by every test file.

``pytest.approx(x, rel=r)`` keeps pytest's default absolute tolerance of 1e-12, and the SI
quantities of a microsphere are smaller than that (mass 2.3e-13 kg, energies 1e-14 J, torques
3.5e-14 N m): a result of 0 would pass such a comparison. Here the default absolute tolerance is
0, so a comparison without ``abs=`` is purely relative and can fail; a comparison with an expected
value of 0 must state its ``abs=`` (and say why it is what it is).
"""

import pytest

try:  # pytest >= 9.2 keeps approx in its own module
    from _pytest.approx import ApproxDecimal, ApproxScalar
except ImportError:
    from _pytest.python_api import ApproxDecimal, ApproxScalar

ApproxScalar.DEFAULT_ABSOLUTE_TOLERANCE = 0.0
ApproxDecimal.DEFAULT_ABSOLUTE_TOLERANCE = 0.0
# the policy took effect (a pytest that keeps the default elsewhere fails here, not silently)
if 1e-13 == pytest.approx(0.0):
    raise RuntimeError("tests/conftest.py could not set pytest.approx's default absolute tolerance to 0")
