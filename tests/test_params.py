"""Contact parameters: validation, constructors and derived constants (Eqs. 3-7, 14-15, 29-32)."""

import math

import pytest

from microimpact import Contact
from microimpact.presets import WALL_1990, get_preset


def test_wall_1990_is_table_1_row_2():
    c = WALL_1990
    assert (c.radius, c.density, c.stiffness, c.adhesion_line_force) == (3.45e-6, 1350.0, 1.776e9, 7.422)
    assert (c.zeta_adhesion, c.zeta_hertz, c.friction) == (29.0, 0.50, 0.15)
    assert c.damping_reference_speed is None
    assert get_preset("WALL1990") is c


def test_table_1_row_1_is_as_printed():
    """Table 1 row 1 of the paper, both ends, as printed (literal values: a mistyped f0 such as 5.430
    must fail here, not only in a regression file made from the code itself)."""
    from microimpact.model.parameters import TABLE1

    small, large = TABLE1["row1_small"], TABLE1["row1_large"]
    assert (small.radius, small.adhesion_line_force) == (1.29e-6, 5.340)
    assert (large.radius, large.adhesion_line_force) == (3.45e-6, 7.390)
    for c in (small, large):
        assert (c.density, c.stiffness, c.zeta_hertz, c.zeta_adhesion, c.friction) == (1350.0, 1.776e9, 0.50, 29.0, 0.15)


def test_scales_of_the_model_notes():
    # model-notes section 5 quotes X = 26 nm, T = 21 ns, m = 2.32e-13 kg (2-3 significant digits)
    c = WALL_1990
    assert c.mass == pytest.approx(2.32e-13, rel=5e-3)
    assert c.length_scale == pytest.approx(26e-9, rel=2e-2)
    assert c.time_scale == pytest.approx(21e-9, rel=2e-2)
    # (2/5) m r^2 with m = (4/3) pi r^3 rho: 1.10555e-24 kg m^2 for r = 3.45 um
    assert c.moment_of_inertia == pytest.approx(0.4 * (4 / 3 * math.pi * 3.45e-6**3 * 1350.0) * 3.45e-6**2, rel=1e-14)
    assert c.moment_of_inertia == pytest.approx(1.10555e-24, rel=1e-5)


def test_time_scale_makes_eq_28_dimensionless():
    # T^2 sqrt(r) K X^(1/2) / m = 1 is the defining property of the corrected Eq. (30)
    c = WALL_1990
    assert c.time_scale**2 * math.sqrt(c.radius) * c.stiffness * math.sqrt(c.length_scale) / c.mass == pytest.approx(1.0, rel=1e-14)


def test_damping_conversion_eqs_14_15_and_31_32():
    c = WALL_1990
    v = 1.0
    c_h, c_a = c.damping_coefficients(v)
    bracket = (c.radius**3 * c.stiffness * math.sqrt(v) / c.mass) ** 0.4  # units of a speed
    assert c_h * bracket == pytest.approx(0.5, rel=1e-14)
    assert c_a * bracket == pytest.approx(29.0, rel=1e-14)
    c1, c2 = c.nondimensional_damping(v)
    assert c1 == pytest.approx(c_h * c.length_scale / c.time_scale, rel=1e-14)
    # C scales as v^(-1/5) with the per-impact reference speed ...
    assert c.nondimensional_damping(32.0)[1] == pytest.approx(c2 / 2.0, rel=1e-13)
    # ... and not at all with a fixed one
    fixed = c.with_(damping_reference_speed=1.0)
    assert fixed.nondimensional_damping(32.0) == pytest.approx((c1, c2), rel=1e-14)


def test_work_of_adhesion_round_trip_eq_7():
    c = Contact.from_work_of_adhesion(3.45e-6, 1350.0, 1.776e9, WALL_1990.work_of_adhesion)
    assert c.adhesion_line_force == pytest.approx(7.422, rel=1e-13)
    assert WALL_1990.work_of_adhesion == pytest.approx(0.2158, abs=1e-4)


def test_from_elastic_eqs_3_4():
    # K = (4/3) E* with 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2
    c = Contact.from_elastic(1e-6, 2000.0, 100e9, 0.3, 200e9, 0.25, work_of_adhesion=0.1)
    e_star = 1.0 / ((1 - 0.3**2) / 100e9 + (1 - 0.25**2) / 200e9)
    assert c.stiffness == pytest.approx(4.0 / 3.0 * e_star, rel=1e-14)
    assert c.work_of_adhesion == pytest.approx(0.1, rel=1e-13)


@pytest.mark.parametrize(
    "field, value",
    [("radius", 0.0), ("radius", -1e-6), ("density", math.nan), ("stiffness", math.inf), ("adhesion_line_force", -1.0),
     ("zeta_hertz", -0.1), ("zeta_adhesion", -1.0), ("friction", -0.01), ("damping_reference_speed", 0.0)],
)
def test_invalid_values_name_the_field(field, value):
    with pytest.raises(ValueError, match=field):
        WALL_1990.with_(**{field: value})


@pytest.mark.parametrize("nu", [-1.0, 0.5, 0.7, math.nan])
def test_poisson_ratio_outside_range(nu):
    with pytest.raises(ValueError, match="poisson_sphere"):
        Contact.from_elastic(1e-6, 2000.0, 100e9, nu, 200e9, 0.25)


def test_contact_is_frozen():
    with pytest.raises(AttributeError):
        WALL_1990.radius = 1.0  # type: ignore[misc]
