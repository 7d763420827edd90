"""The emulator of the ring law's e_n over its groups (microimpact.solvers.emulator), judged by the solver.

A small table (one cell of the groups' box, a coarse tolerance: a few seconds to build) is built into
a temporary cache; its values are compared with engine solves at rtol 1e-12 of dimensional contacts
whose groups fall at random points of the box, and of contacts outside it, which must be solved.
"""

import math

import numpy as np
import pytest

from microimpact import Contact, simulate_impact
from microimpact.model import reduction as rd
from microimpact.model.parameters import TABLE1_ROW2
from microimpact.solvers import emulator as em, engine_threads
from microimpact.solvers.family import normal_restitution
from microimpact.studies import emulator_benchmark as bench

#: one cell: C1 over a factor 2, C2 over a factor 2 (TABLE1_ROW2 at 1 m/s: C1 = 4e-3, C2 = 0.23)
SMALL = {"hertz_damping": (3e-3, 6e-3), "adhesion_damping": (0.15, 0.3), "incident_speed": (1e-2, 1e2)}
TOL = 1e-4
#: the judge: engine solves at rtol 1e-12 have e_n errors ~1e-11, far below TOL
JUDGE_RTOL = 1e-12


@pytest.fixture(scope="module")
def table(private_emulator_cache):
    return em.ring_emulator(TOL, SMALL)


def _random_groups(rng, n, box=SMALL):
    """n points of the box, log-uniform in each group."""
    return {k: np.exp(rng.uniform(*np.log(box[k]), n)) for k in ("incident_speed", "hertz_damping", "adhesion_damping")}


def _judge(y0, c1, c2):
    """e_n of a dimensional contact with these groups (radius, density, stiffness, w_A drawn at random)."""
    rng = np.random.default_rng(abs(hash((y0, c1, c2))) % 2**32)
    contact, v = rd.contact_with_groups("ring", radius=10 ** rng.uniform(-7, -4), density=10 ** rng.uniform(3, 4),
                                        stiffness=10 ** rng.uniform(8, 11), work_of_adhesion=10 ** rng.uniform(-2, 0),
                                        incident_speed=y0, hertz_damping=c1, adhesion_damping=c2)
    with engine_threads(1):  # one small solve: a second thread only waits
        return float(normal_restitution(contact, [v], rtol=JUDGE_RTOL, family=False)[0])


def test_the_table_meets_its_tolerance_at_random_points(table):
    g = _random_groups(np.random.default_rng(3), 100)
    e, captured, solve = table.evaluate(g["incident_speed"], g["hertz_damping"], g["adhesion_damping"])
    assert solve.mean() < 0.05  # only the guard band and failing pieces: a few percent at most
    want = np.array([_judge(*p) for p in zip(*(g[k][~solve] for k in ("incident_speed", "hertz_damping",
                                                                       "adhesion_damping")))])
    assert np.array_equal(captured[~solve], want == 0.0)
    assert np.max(np.abs(e[~solve] - want)) <= TOL
    assert 0.0 < table.max_check_error <= TOL


def test_just_above_the_capture_speed_the_root_is_resolved(table):
    """e_n rises like sqrt(y0 - y_c): points within a factor 1.001 above y_c, outside the guard band."""
    c1, c2 = 4e-3, 0.2
    contact, u = em._canonical(c1, c2)
    with engine_threads(1):
        yc, state, _ = em._capture_speed(c1, c2, SMALL["incident_speed"])
        y0 = yc * (1.0 + np.geomspace(1e-3, 1e-1, 20))
        want = normal_restitution(contact, y0 * u, rtol=JUDGE_RTOL, family=False)
    assert state == em._OK
    e, captured, solve = table.evaluate(y0, c1, c2)
    assert not captured.any() and not solve.any()
    assert np.max(np.abs(e - want)) <= TOL
    below, _, _ = table.evaluate(yc * 0.99, c1, c2)
    assert table.evaluate(yc * 0.99, c1, c2)[1] and below == 0.0


def test_a_tolerance_below_the_estimates_sends_everything_to_the_solver(table):
    g = _random_groups(np.random.default_rng(4), 50)
    e, captured, solve = table.evaluate(g["incident_speed"], g["hertz_damping"], g["adhesion_damping"], tol=1e-14)
    assert solve[~captured].all()  # a captured point needs no estimate: below the band it is captured


def test_restitution_of_many_contacts_against_simulate_impact(table):
    rng = np.random.default_rng(5)
    contacts, speeds, inside = [], [], []
    for k in range(12):
        g = {n: float(x[0]) for n, x in _random_groups(rng, 1).items()}
        if k % 4 == 3:
            g["hertz_damping"] = 0.5  # outside the box: solved
        c, v = rd.contact_with_groups("ring", radius=10 ** rng.uniform(-6, -5), density=2000.0, stiffness=1e10,
                                      work_of_adhesion=0.1, **g)
        contacts.append(c)
        speeds.append([v, 1.7 * v])  # row i: contact i; the second speed changes C1, C2 (per-impact v_ref)
        inside.append(k % 4 != 3)
    r = em.restitution(contacts, np.array(speeds), tol=TOL, domain=SMALL)
    assert r.e_n.shape == (12, 2)
    assert r.solved[~np.array(inside)].all()
    for i, c in enumerate(contacts):
        for j, v in enumerate(speeds[i]):
            want = simulate_impact(c, v, rtol=JUDGE_RTOL)
            assert r.captured[i, j] == (want.outcome == "capture")
            assert abs(r.e_n[i, j] - want.e_n) <= TOL


def test_other_laws_are_solved(table):
    c = TABLE1_ROW2.with_(adhesion_line_force=0.0)  # the Hertz law: one group, not the ring law's three
    v = np.array([0.5, 3.0, 30.0])
    r = em.restitution(c, v, tol=TOL, domain=SMALL)
    assert r.solved.all()
    assert np.array_equal(r.e_n, normal_restitution(c, v, rtol=TOL * 1e-2))


def test_the_table_is_cached_outside_the_package_and_reloaded(table, tmp_path, monkeypatch):
    path = em._cache_path(TOL, SMALL)
    assert path.exists() and path.parent == em.cache_dir()
    assert "site-packages" not in str(path) and em.__file__ not in str(path.parent)
    em._LOADED.clear()
    again = em.ring_emulator(TOL, SMALL)
    assert again is not table
    assert all(np.array_equal(again.arrays[k], table.arrays[k]) for k in table.arrays)
    monkeypatch.setattr(em, "_SETTINGS", em._SETTINGS + ("changed",))
    assert em._cache_path(TOL, SMALL) != path  # another setting or an edited law: another table


def test_cache_dir_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("MICROIMPACT_CACHE", str(tmp_path / "a"))
    assert em.cache_dir() == tmp_path / "a"
    monkeypatch.delenv("MICROIMPACT_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "x"))
    assert em.cache_dir() == tmp_path / "x" / "microimpact"


@pytest.mark.parametrize("contacts, speeds, error, message", [
    ([TABLE1_ROW2, TABLE1_ROW2], [1.0, 2.0, 3.0], ValueError, "first axis"),
    (["not a contact"], [1.0], TypeError, "Contact"),
    (TABLE1_ROW2, [1.0, -2.0], ValueError, "speeds must be finite numbers > 0"),
])
def test_bad_input_is_refused_by_name(contacts, speeds, error, message):
    with pytest.raises(error, match=message):
        em.restitution(contacts, speeds, tol=TOL, domain=SMALL)


def test_bad_tolerance_is_refused():
    with pytest.raises(ValueError, match="tol must be"):
        em.restitution(TABLE1_ROW2, [1.0], tol=0.0)


def test_the_table_tolerance_is_the_power_of_ten_below():
    assert em.table_tolerance(3e-6) == pytest.approx(1e-6, rel=1e-12, abs=0)
    assert em.table_tolerance(1e-6) == pytest.approx(1e-6, rel=1e-12, abs=0)
    assert math.isclose(em.surface_tolerance(1e-4), 1e-6)


def test_the_canonical_contact_has_the_groups_it_is_given():
    c, u = em._canonical(2e-3, 0.4)
    g = rd.groups(c, 3.0 * u)
    assert [round(x, 12) for x in g.values] == [3.0, 2e-3, 0.4]
    assert isinstance(c, Contact)


def test_the_benchmark_measures_all_three_side_by_side(table):
    out = bench.run_emulator_benchmark(contacts=4, impacts=3, tol=TOL, seed=2, repeats=1, domain=SMALL, sample=6,
                                       dop853_sample=2, solver_contacts=2)
    assert out["impacts"] == 12 and out["tol"] == TOL and out["reference"]["sample_impacts"] == 6
    assert set(out["time_per_impact_s"]) == {"emulator", "table_kernel", "solver", "dop853", "dop853_reference",
                                       "emulator_after_dop853"}
    errors = out["errors_against_reference"]
    assert errors["emulator"]["max_error_e_n"] <= TOL  # the table where it decides, the solver elsewhere
    assert errors["emulator"]["outcome_disagreements"] == 0
    assert out["speed_ratio_dop853_over_emulator"] == pytest.approx(
        out["time_per_impact_s"]["dop853"] / out["time_per_impact_s"]["emulator"], rel=1e-12, abs=0)
    assert sum(out["fallback_impacts_by_reason"].values()) == round(out["fraction_solved_by_emulator_fallback"] * 12)


@pytest.mark.parametrize("args, message", [(["--contacts", "0"], "must be >= 1"), (["--sample", "0"], "must be >= 1"), (["--tol", "2"], "--tol must lie")])
def test_the_benchmark_command_refuses_bad_options(args, message, capsys):
    with pytest.raises(SystemExit) as exit_:
        bench.main(args)
    assert exit_.value.code == 2 and message in capsys.readouterr().err


def test_the_fallback_on_the_paper_microsphere_box_is_a_small_fraction(table):
    """Log-uniform impacts over the box (the paper's microsphere, Table 1 row 2: C1 ~ 4e-3, C2 ~ 0.23 at
    1 m/s): the table leaves to the solver only the guard band (relative width g <= 4e-4 by
    surface_tolerance) and pieces below NEAR_CAPTURE_T or MIN_PIECE (ln(y0 / y_c) < ln(1e4) / 1024, a share
    <= 1/1024 of the ln y0 range above y_c). Bound: 1 % (a cell left to the solver, as when the check
    rejected whole cells, is the whole cell)."""
    g = _random_groups(np.random.default_rng(6), 20_000)
    reasons = table.fallback_reasons(g["incident_speed"], g["hertz_damping"], g["adhesion_damping"])
    solved = sum(reasons.values())
    assert solved <= 0.01 * 20_000, reasons
    assert reasons["cell left to the solver"] == 0 and reasons["outside the domain"] == 0
    out = {k: v * 10.0 for k, v in g.items()}  # y0, C1 and C2 ten times the box's: all outside
    assert table.fallback_reasons(out["incident_speed"], out["hertz_damping"], out["adhesion_damping"])[
        "outside the domain"] == 20_000


def test_inside_the_guard_band_the_solver_decides(table):
    """About y_c the table answers neither capture nor rebound: y0 within the guard band of the true
    capture speed (found by multisection, the solver's) is left to the solver, and its answer
    there is the judge's; just outside the band the table decides."""
    c1, c2 = 4e-3, 0.2
    with engine_threads(1):
        yc, state, _ = em._capture_speed(c1, c2, SMALL["incident_speed"])
    cell = em._find_cell(math.log(c1), math.log(c2), *(table.arrays[k] for k in ("box", "roots", "children", "leaf")))[0]
    guard = float(table.arrays["guard"][cell])
    assert state == em._OK and 0.0 < guard < 1e-3
    inside = yc * np.exp(np.array([-0.25, -0.1, 0.1, 0.25]) * guard)  # |offset| + surface error eps <= g (g >= 2 eps)
    e, captured, solve = table.evaluate(inside, c1, c2)
    assert solve.all() and table.fallback_reasons(inside, c1, c2)["guard band about the capture speed"] == 4
    outside = yc * np.exp(np.array([-3.0, 3.0]) * guard)
    e, captured, solve = table.evaluate(outside, c1, c2)
    assert not solve.any() and captured.tolist() == [True, False]


def test_the_fallback_resolves_near_capture_impacts_tighter():
    """A solve's e_n error near capture grows like ~1.2 rtol / e_n: at rtol = tol / 100 it misses tol = 1e-8
    below e_n ~ 0.012, so the fallback solves those again at tol e_n / 12. Judged at rtol 1e-13."""
    c1, c2, tol = 4e-3, 0.2, 1e-8
    contact, u = em._canonical(c1, c2)
    with engine_threads(1):
        yc = em._capture_speed(c1, c2, SMALL["incident_speed"])[0]
        v = yc * (1.0 + np.array([1e-5, 1e-4, 1e-3])) * u  # e_n ~ 3e-3 to 3e-2
        want = normal_restitution(contact, v, rtol=1e-13, family=False)
        got = em.fallback_restitution(contact, v, tol)
        loose = normal_restitution(contact, v, rtol=tol * em.FALLBACK_RTOL)
    assert np.all((want > 1e-3) & (want < 0.1))
    assert np.max(np.abs(got - want)) <= tol
    assert np.max(np.abs(loose - want)) > tol  # what the one solve at tol / 100 would have given


# ------------------------------------------------------------------ the tables shipped with the package
def test_every_shipped_table_is_current_and_none_is_stale():
    names = {em._table_name(tol, dict(domain)) for tol, domain in em.SHIPPED}
    present = {p.name for p in em.shipped_dir().glob("ring-*.npz")}
    hint = ('a change of the law, the engine or the emulator changed the tables\' key: rerun '
            '`python -c "from microimpact.solvers.emulator import ship_tables; ship_tables()"` and commit '
            'toolkit/microimpact/data/emulator/')
    assert names <= present, f"missing {sorted(names - present)}; {hint}"
    assert present <= names, f"stale {sorted(present - names)}; {hint}"


def test_the_shipped_table_is_read_not_built(private_emulator_cache):
    tol, domain = em.SHIPPED[0]
    em._LOADED.clear()
    shipped = em.ring_emulator(tol, domain)
    assert not (em.cache_dir() / em._table_name(tol, dict(domain))).exists()  # read from the package, not built
    assert shipped.tolerance == pytest.approx(tol, rel=1e-12, abs=0)
    assert shipped.max_check_error <= tol  # the build's own certification, stored with the table


def test_the_shipped_table_meets_its_tolerance_against_the_solver(private_emulator_cache):
    """300 impacts at random points of the shipped box (log-uniform groups, each a dimensional contact
    drawn at random), judged by solves at rtol 1e-12 (e_n error ~1e-11, far below tol 1e-6)."""
    tol, domain = em.SHIPPED[0]
    em._LOADED.clear()
    table = em.ring_emulator(tol, domain)
    g = _random_groups(np.random.default_rng(7), 300, box=domain)
    e, captured, solve = table.evaluate(g["incident_speed"], g["hertz_damping"], g["adhesion_damping"], tol)
    assert solve.mean() < 0.1  # the box is the table's: few impacts go to the solver
    judged = np.array([_judge(*x) for x in zip(g["incident_speed"][~solve], g["hertz_damping"][~solve],
                                                g["adhesion_damping"][~solve])])
    assert np.max(np.abs(e[~solve] - judged)) <= tol
    assert np.array_equal(captured[~solve], judged == 0.0)
