"""The nondimensional groups of the normal impact (microimpact.model.reduction), law by law.

The claim tested: contacts whose dimensional parameters differ by orders of magnitude but whose
groups are equal have the same e_n, contact (or capture) time over the law's time unit, friction
impulse over m v and largest penetration over the law's length unit; changing one group changes
e_n; and no law's groups can be fewer (the rank of the outputs' Jacobian). The solver that
decides is the toolkit's engine, fed the dimensional contacts; one check integrates the SI equation
of motion, Eq. (27), with scipy in variables of its own (x / r, t v / r), not the toolkit's scales.
"""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from microimpact import simulate_impact
from microimpact.model import reduction as rd
from microimpact.model.parameters import TABLE1_ROW2
from microimpact.solvers import MIN_RTOL

pytestmark = pytest.mark.filterwarnings("ignore::microimpact.model.adhesion_models.AdhesionRegimeWarning")

#: Why 1e-12. Two contacts with equal groups give the engine the same nondimensional problem up to
#: the rounding of the groups (a few ulp, ~1e-15 relative), which moves each output by a few ulp
#: times its condition number; but an adaptive solver can accept a step in one solve that it rejects
#: in the other (the error estimate sits at the tolerance), and then the two differ by up to the
#: solver's own error, a small multiple of rtol. At rtol = MIN_RTOL (2.2e-14) the largest difference
#: seen over every law and 8 random contacts each was 2.7e-13 (the tsuji law; 1e-14 for the ring law),
#: so 1e-12 has margin, while any real dependence on a dimensional parameter fails it (changing the
#: exponent 1/5 of Eqs. (14)-(15) to 1/4 in the inverse fails 13 tests here).
SAME = 1e-12
RTOL = MIN_RTOL * 1.01  # the smallest tolerance the solvers accept (MIN_RTOL itself, up to rounding)

#: group values per law: rebounds for most (the rebound's e_n is the sharpest check), one capture
_GROUPS = {"incident_speed": 30.0, "hertz_damping": 0.02, "adhesion_damping": 0.3, "dem_damping": 0.4}
_RESTITUTION_LAWS = ("hertz+tsuji", "hertz+coeff_restitution")


def _group_values(law, **changes):
    values = dict(_GROUPS, **changes)
    if law.startswith("jkr"):  # the JKR laws' damping acts over a larger contact: less of it to rebound
        values.update(adhesion_damping=0.01, dem_damping=0.03)
    if law in _RESTITUTION_LAWS:
        values["dem_damping"] = 0.6  # a damping factor: e = 0.6 is a sane restitution
    return {n: values[n] for n in rd.LAW_GROUPS[law]}


def _dimensional(rng):
    """A sphere and material drawn over orders of magnitude: r 0.1-100 um, rho, K, w_A, and a speed
    for the laws in which the speed is not a group."""
    return dict(radius=10 ** rng.uniform(-7, -4), density=10 ** rng.uniform(2.5, 4.5),
                stiffness=10 ** rng.uniform(7, 11), work_of_adhesion=10 ** rng.uniform(-3, 0),
                normal_speed=10 ** rng.uniform(-1, 1))


def _outputs(contact, speed):
    """The nondimensional outputs of one impact and its outcome."""
    g = rd.groups(contact, speed)
    r = simulate_impact(contact, speed, rtol=RTOL)
    if r.outcome == "capture":  # e_n is 0 and the contact time inf; what is left is the capture time
        return r.outcome, np.array([r.capture_time / g.time, r.max_penetration / g.length])
    return r.outcome, np.array([r.e_n, r.contact_time / g.time, r.friction_impulse / (contact.mass * speed),
                                r.max_penetration / g.length])


def _spread(law, values, n=4, seed=0):
    """The largest relative difference of the outputs over n contacts with the same groups, and the outcomes."""
    rng = np.random.default_rng(seed)
    found = [_outputs(*rd.contact_with_groups(law, **_dimensional(rng), **values)) for _ in range(n)]
    outcomes = {o for o, _ in found}
    ref = found[0][1]
    # relative, and exact where an output is 0 in every solve (a JKR sphere below its sticking speed is
    # captured at first contact: capture time 0)
    scale = np.where(ref == 0.0, 1.0, np.abs(ref))
    return max(float(np.max(np.abs(x - ref) / scale)) for _, x in found), outcomes


@pytest.mark.parametrize("law", list(rd.LAW_GROUPS))
def test_same_groups_same_outputs_for_every_law(law):
    values = _group_values(law)
    spread, outcomes = _spread(law, values)
    assert len(outcomes) == 1
    assert spread <= SAME, f"{law}: {spread:.3g}"


@pytest.mark.parametrize("law", ["ring", "jkr", "dmt", "jkr_force+mass_velocity"])
def test_same_groups_same_capture(law):
    values = _group_values(law, incident_speed=0.5)
    spread, outcomes = _spread(law, values, seed=1)
    assert outcomes == {"capture"}
    assert spread <= SAME, f"{law}: {spread:.3g}"


def _e_n(law, **values):
    return simulate_impact(*rd.contact_with_groups(law, **values), rtol=1e-12).e_n


@pytest.mark.parametrize("law", list(rd.LAW_GROUPS))
def test_changing_one_group_changes_e_n(law):
    """Each group on its own moves e_n, by far more than the solver's error: none is redundant."""
    values = _group_values(law)
    e0 = _e_n(law, **values)
    assert 0.0 < e0 < 1.0
    for name in values:
        changed = dict(values, **{name: values[name] * 1.05})
        assert abs(_e_n(law, **changed) - e0) > 1e-5, f"{law}: e_n does not move with {name}"


def _log_jacobian(law, values, h=1e-4):
    """Central differences of (e_n, t_c / T, J / (m v), x_max / L) in the logarithms of the groups."""
    columns = []
    for name in values:
        up, down = (_outputs(*rd.contact_with_groups(law, **dict(values, **{name: values[name] * math.exp(s)})))[1]
                    for s in (h, -h))
        columns.append((up - down) / (2 * h))
    return np.array(columns).T


@pytest.mark.parametrize("law", ["ring", "jkr", "dmt", "jkr_force+viscoelastic"])
def test_the_groups_are_minimal(law):
    """Rank of the Jacobian = the number of groups: were the outputs functions of fewer combinations
    of the groups, the rank would be smaller. Noise of a difference: ~1e-13 / 1e-4 = 1e-9, and the
    truncation error h^2 ~ 1e-8; the smallest singular value is asserted above 1e-5 of the largest
    (measured: 7.6e-4 for jkr_force, the smallest, to 5e-2)."""
    values = _group_values(law)
    sv = np.linalg.svd(_log_jacobian(law, values), compute_uv=False)
    assert sv.size == len(values)
    assert sv[-1] > 1e-5 * sv[0], sv


def test_a_hand_derived_similarity_not_through_the_inverse():
    """r -> 10 r at the same rho, K, w_A: f0 ~ r^(1/3) (Eq. (7)), X ~ r^(1/3), T ~ r^(7/6), so X / T ~ r^(-5/6);
    C1 = zeta_H (X / r) y0^(-1/5) then asks zeta ~ r^(2/3). Worked by hand, not with the module."""
    c, v, lam = TABLE1_ROW2, 5.0, 10.0
    big = c.at_radius(c.radius * lam, zeta_hertz=c.zeta_hertz * lam ** (2 / 3),
                      zeta_adhesion=c.zeta_adhesion * lam ** (2 / 3))
    v_big = v * lam ** (-5 / 6)
    assert [round(a / b, 12) for a, b in zip(rd.groups(big, v_big).values, rd.groups(c, v).values)] == [1.0] * 3
    a, b = simulate_impact(c, v, rtol=RTOL), simulate_impact(big, v_big, rtol=RTOL)
    assert a.outcome == b.outcome == "rebound"
    assert b.e_n == pytest.approx(a.e_n, rel=SAME, abs=0)
    assert b.contact_time / big.time_scale == pytest.approx(a.contact_time / c.time_scale, rel=SAME, abs=0)


def _si_restitution(contact, v):
    """e_n from Eq. (27) in SI, integrated with scipy's DOP853 in chi = x / r and theta = t v / r with the
    Sundman time d theta = sqrt(chi) d sigma (the sqrt(x) force is smooth in s = sqrt(chi)). Uses the
    contact's m, r, K, f0 and C_H, C_A of Eqs. (14)-(15) only: none of the toolkit's scales."""
    m, r = contact.mass, contact.radius
    a_h, b_a = math.sqrt(r) * contact.stiffness, 2 * math.pi * contact.adhesion_line_force * math.sqrt(r)
    c_h, c_a = contact.damping_coefficients(v)
    k = r / (m * v * v)

    def rhs(_, u):
        s, y = u
        return [0.5 * y, k * (-a_h * r**1.5 * s**4 * (1 + c_h * v * y) + b_a * math.sqrt(r) * s * s * (1 - c_a * v * y))]

    def separation(_, u):
        return u[0]

    separation.terminal, separation.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 1e9), [0.0, 1.0], method="DOP853", rtol=1e-12, atol=1e-15, events=separation)
    assert sol.status == 1
    return -sol.y_events[0][0][1]


def test_same_groups_same_e_n_by_an_independent_si_integration():
    """Two contacts two decades apart in radius with the same groups rebound alike in an SI integration that
    shares nothing with the toolkit's nondimensional form; 1e-9: scipy's error at rtol 1e-12 on this
    smooth Sundman form is ~1e-11 per solve (the engine at MIN_RTOL agrees to the same digits)."""
    values = dict(incident_speed=6.0, hertz_damping=0.01, adhesion_damping=0.2)
    a = rd.contact_with_groups("ring", radius=1e-6, density=1200.0, stiffness=1e9, work_of_adhesion=0.05, **values)
    b = rd.contact_with_groups("ring", radius=1e-4, density=8000.0, stiffness=2e11, work_of_adhesion=1.0, **values)
    e_a, e_b = _si_restitution(*a), _si_restitution(*b)
    assert 0.1 < e_a < 0.9
    assert e_b == pytest.approx(e_a, rel=1e-9, abs=0)
    assert simulate_impact(*a, rtol=RTOL).e_n == pytest.approx(e_a, rel=1e-9, abs=0)


@pytest.mark.parametrize("reference_speed", [None, 0.3])
def test_paper_zeta_enters_with_x_over_r(reference_speed):
    """C1 = zeta_H (X / r) y_ref^(-1/5) (module docstring), against groups()'s route through Eqs. (14)-(15)."""
    c = TABLE1_ROW2.with_(damping_reference_speed=reference_speed)
    for v in (0.05, 1.0, 40.0):
        g = rd.groups(c, v)
        c1, c2 = rd.paper_damping_groups(c, v)
        assert c1 == pytest.approx(g.hertz_damping, rel=1e-14, abs=0)
        assert c2 == pytest.approx(g.adhesion_damping, rel=1e-14, abs=0)


def test_groups_of_an_array_of_speeds_are_those_of_each_speed():
    v = np.array([0.1, 1.0, 10.0])
    for c in (TABLE1_ROW2, TABLE1_ROW2.with_(adhesion_line_force=0.0), TABLE1_ROW2.with_(normal_model="jkr")):
        many = rd.groups(c, v)
        for i, vi in enumerate(v):
            one = rd.groups(c, float(vi))
            assert np.allclose(np.array(many.values)[:, i], one.values, rtol=1e-15, atol=0)


@pytest.mark.parametrize("law", list(rd.LAW_GROUPS))
def test_the_inverse_gives_back_the_groups(law):
    values = _group_values(law)
    c, v = rd.contact_with_groups(law, radius=2e-5, density=5000.0, stiffness=3e10, work_of_adhesion=0.2, **values)
    g = rd.groups(c, v)
    assert g.law == law
    assert np.allclose(g.values, [values[n] for n in g.names], rtol=1e-13, atol=0)


@pytest.mark.parametrize("law, values, message", [
    ("plastic", {}, "law must be one of"),
    ("ring", {"incident_speed": 1.0}, "has the groups incident_speed, hertz_damping, adhesion_damping"),
    ("hertz", {"hertz_damping": 0.1, "incident_speed": 2.0}, "has the groups hertz_damping"),
    ("ring", {"incident_speed": -1.0, "hertz_damping": 0.1, "adhesion_damping": 0.1}, "incident_speed must be"),
])
def test_bad_groups_are_refused_by_name(law, values, message):
    with pytest.raises(ValueError, match=message):
        rd.contact_with_groups(law, **values)


def test_ring_groups_of_many_contacts_are_those_of_groups():
    rng = np.random.default_rng(9)
    contacts = [TABLE1_ROW2.with_(radius=10 ** rng.uniform(-7, -4), zeta_hertz=rng.uniform(0, 2),
                                  damping_reference_speed=None if k % 2 else 0.7) for k in range(6)]
    v = 10 ** rng.uniform(-1, 2, (6, 4))
    many = rd.ring_groups(contacts, v)
    for i, c in enumerate(contacts):
        one = rd.groups(c, v[i])
        for got, want in zip(many, one.values):
            assert np.allclose(got[i], want, rtol=1e-14, atol=0)
