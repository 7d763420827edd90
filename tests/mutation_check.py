"""Mutation check of the physics: every one-line mutation below must be killed by the fast tests.

Each mutation changes one physics line of ``toolkit/microimpact`` (a coefficient of a force law,
a scale, an equation's sign, a tabulated parameter) in a copy of the package; the physics test
files (:data:`KILLERS`, the regression baseline left out: it is made from the code itself) then run
against the copy, on a numba cache of its own, and must fail. A mutation they do not notice is a
gap in the tests. First the unmutated copy must pass the same tests, else every mutation would
look killed.

    python tests/mutation_check.py --out docs/mutations.json                     # all (tens of minutes)
    python tests/mutation_check.py --select "solvers/|dem_" --skip-baseline    # a subset, after the suite passed

Exit status 0 when every mutation was killed, 1 when one survived (listed), 2 on a usage error or a
failing baseline.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

#: the fast physics tests that must kill every mutation (no pipeline runs, no studies)
KILLERS = ["tests/test_params.py", "tests/test_engine.py", "tests/test_adhesion_models.py",
           "tests/test_contact_models.py", "tests/test_dynamics.py", "tests/test_independent_physics.py",
           "tests/test_agreement.py", "tests/test_reference.py", "tests/test_dem_damping.py",
           "tests/test_dem_tangential.py", "tests/test_dem_rolling.py"]

#: (file under toolkit/microimpact, text that occurs exactly once, its mutation, what it breaks)
MUTATIONS = [
    ("model/contact.py", "return 4.0 / 3.0 * math.pi * self.radius**3 * self.density",
     "return 4.1 / 3.0 * math.pi * self.radius**3 * self.density", "sphere mass"),
    ("model/contact.py", "return 0.4 * self.mass * self.radius**2", "return 0.5 * self.mass * self.radius**2",
     "moment of inertia of a solid sphere"),
    ("model/contact.py", "(9.0 * self.stiffness * self.radius)", "(8.0 * self.stiffness * self.radius)",
     "length scale X, Eq. (29)"),
    ("model/contact.py", "math.sqrt(2.0 * math.pi * self.radius * self.adhesion_line_force * self.stiffness)",
     "math.sqrt(2.1 * math.pi * self.radius * self.adhesion_line_force * self.stiffness)", "time scale T, Eq. (30)"),
    ("model/contact.py", "return self.zeta_hertz / scale, self.zeta_adhesion / scale",
     "return self.zeta_adhesion / scale, self.zeta_hertz / scale", "C_H and C_A swapped, Eqs. (14)-(15)"),
    ("model/contact.py", "(9.0 / (2.0 * math.pi) * stiffness * radius * work_of_adhesion**2)",
     "(9.0 / (2.2 * math.pi) * stiffness * radius * work_of_adhesion**2)", "f0 from w_A, Eq. (7)"),
    ("model/law.py", "TWIST_TORQUE_FACTOR = 3.0 * math.pi / 16.0", "TWIST_TORQUE_FACTOR = 3.0 * math.pi / 15.0",
     "twist torque factor"),
    ("model/law.py", "stiffness * np.maximum(penetration, 0.0) ** 1.5", "stiffness * np.maximum(penetration, 0.0) ** 1.4",
     "Hertz force exponent, Eq. (2)"),
    ("model/law.py", "return -2.0 * math.pi * adhesion_line_force", "return -2.1 * math.pi * adhesion_line_force",
     "adhesion ring force, Eq. (5)"),
    ("model/law.py", "f_a * (1.0 - c_adhesion * penetration_rate)", "f_a * (1.0 + c_adhesion * penetration_rate)",
     "sign of the adhesion damping, Eq. (27)"),
    ("model/law.py", "return a_a * root * (1.0 - c2 * y)", "return a_a * root * (1.0 - 0.9 * c2 * y)",
     "nondimensional adhesion damping, Eq. (33)"),
    ("model/law.py", "0.5 * y * y + a_h * 0.4 * s3 * s * s", "0.5 * y * y + a_h * 0.41 * s3 * s * s",
     "contact energy (Hertz part)"),
    ("model/kinematics.py", "speed * math.sin(a) * math.cos(th), speed", "speed * math.sin(a) * math.cos(2.0 * th), speed",
     "incident tangential velocity, azimuth"),
    ("model/kinematics.py", "return v_t + radius * omega_tp, v_tp - radius * omega_t",
     "return v_t - radius * omega_tp, v_tp - radius * omega_t", "contact-point slip, Eqs. (19)-(20)"),
    ("model/tangential.py", "return 2.0 * mass * slip_speed / (7.0 * friction)",
     "return 2.0 * mass * slip_speed / (6.0 * friction)", "friction impulse that ends sliding (2/7 rule)"),
    ("model/parameters.py", '"row1_small": Contact(radius=1.29e-6, adhesion_line_force=5.340',
     '"row1_small": Contact(radius=1.29e-6, adhesion_line_force=5.430', "Table 1 row 1, f0"),
    ("model/tangential_compliance.py", "return 8.0 * shear_modulus * np.asarray(contact_radius, dtype=float)",
     "return 7.0 * shear_modulus * np.asarray(contact_radius, dtype=float)", "Mindlin stiffness k_t = 8 G* a"),
    ("solvers/normal_models.py", "else 1.0), 6.0 ** (1.0 / 3.0)", "else 1.0), 5.0 ** (1.0 / 3.0)",
     "JKR settled contact, q^3 = 6"),
    ("model/dem_damping.py", "        return coef * contact.mass, 1.0", "        return coef * contact.mass, 0.9",
     "viscoelastic damping eta = eta_n0 m a"),
    ("model/dem_damping.py", "return math.sqrt(2.0) * sum(", "return math.sqrt(1.9) * sum(",
     "tsuji damping factor, sqrt(2) alpha(e)"),
    ("model/adhesion_models.py", "    return 0.4 * s**5", "    return 0.41 * s**5", "Hertz potential (2/5) s^5"),
    ("model/dem_tangential.py", "return abs(elastic_force + 2.0 * pulloff_force)",
     "return abs(elastic_force + 1.9 * pulloff_force)", "LAMMPS's friction limit with adhesion, |F_ne + 2 F_po|"),
    ("model/dem_tangential.py", "return abs(elastic_force + damping_force)", "return abs(elastic_force)",
     "LAMMPS's Hertz friction limit counts the damping, |F_ne + F_nd|"),
    ("model/dem_tangential.py", "return stiffness * contact_radius", "return 1.01 * stiffness * contact_radius",
     "LAMMPS's Mindlin spring k_t a"),
    ("model/dem_tangential.py", "        rate = rate + radius_rate * history", "        rate = rate + 0.5 * radius_rate * history",
     "LAMMPS's mindlin_rescale, H scaled by a_new / a_old while a falls"),
    ("model/dem_tangential.py", "rate = -stiffness * slip_velocity if tangential_model in FORCE_HISTORY_MODELS",
     "rate = -0.99 * stiffness * slip_velocity if tangential_model in FORCE_HISTORY_MODELS",
     "LAMMPS's mindlin/force, dF = -k u dt"),
    ("model/dem_rolling.py", "return -radius * omega_tp, radius * omega_t", "return radius * omega_tp, radius * omega_t",
     "LAMMPS's rolling velocity R omega x n_w"),
    ("solvers/dem_tangential.py", "dw1, dw2 = g * law.spin * (r1 - f1), g * law.spin * (r2 - f2)",
     "dw1, dw2 = g * law.spin * (r1 + f1), g * law.spin * (r2 + f2)", "rolling velocity's response to both forces"),
    ("solvers/dem_tangential.py", "rcap, drcap = law.mu_r * n0, law.mu_r * dn0",
     "rcap, drcap = 1.01 * law.mu_r * n0, 1.01 * law.mu_r * dn0", "LAMMPS's rolling limit mu_roll F_n0"),
    ("solvers/dopri.py", "B1, B3, B4, B5, B6 = 35.0 / 384.0, 500.0 / 1113.0", "B1, B3, B4, B5, B6 = 35.0 / 384.0, 500.0 / 1131.0",
     "Dormand-Prince weight b3 (the core's order)"),
    ("solvers/dopri.py", "return math.sqrt(scaled_error_sum(u0, u1, err, atol, rtol, n) / n)",
     "return 1e-3 * math.sqrt(scaled_error_sum(u0, u1, err, atol, rtol, n) / n)", "the core's error norm"),
    ("solvers/coupled.py", "_rolling_state(states, held, p[0, 8])", "_rolling_state(states, rows, p[0, 8])",
     "a frictionless captured sphere set rolling"),
    ("solvers/coupled.py", "loss = p[rows, 8] * p[rows, 10] * j_tail", "loss = p[rows, 10] * j_tail",
     "rolling resistance of a captured tail without k = m r^2 / I"),
    ("model/tangential_compliance.py", "rate = (branch_slip * stiffness / (1.5 * branch_span)",
     "rate = (branch_slip * stiffness / (1.4 * branch_span)", "hysteretic branch rate, dT = k_t theta d delta"),
    ("model/tangential_compliance.py", "(branch_coordinate <= 0.0 and rate < 0.0)",
     "(branch_coordinate <= -1.0 and rate < 0.0)", "hysteretic turning point held while the load falls"),
    ("model/tangential_compliance.py", "return (1.0 - exponent) * (1.0 - branch_span) * limit_rate / limit",
     "return (1.0 - 0.5 * exponent) * (1.0 - branch_span) * limit_rate / limit",
     "held turning point's force ~ F_lim^k (the readings compared with Kharaz)"),
]


def _run_tests(package_root: Path, cache: Path, timeout: float) -> tuple[int, float, str]:
    env = dict(os.environ, PYTHONPATH=str(package_root), NUMBA_CACHE_DIR=str(cache), PYTHONWARNINGS="ignore",
               MPLBACKEND="Agg")
    start = time.monotonic()
    try:
        proc = subprocess.run([sys.executable, "-m", "pytest", "-x", "-q", "-p", "no:cacheprovider", *KILLERS],
                              cwd=REPO, env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return -1, time.monotonic() - start, "timed out"
    failed = [ln for ln in proc.stdout.splitlines() if ln.startswith("FAILED") or ln.startswith("ERROR")]
    return proc.returncode, time.monotonic() - start, failed[0] if failed else proc.stdout.strip().splitlines()[-1:][0]


def _copy_package(workdir: Path) -> Path:
    root = workdir / "toolkit"
    shutil.copytree(REPO / "toolkit" / "microimpact", root / "microimpact",
                    ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
    return root


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--only", type=int, help="run only the first N mutations")
    p.add_argument("--select", metavar="REGEX",
                   help="run only the mutations whose file or description matches REGEX (after --only)")
    p.add_argument("--out", type=Path, help="JSON summary")
    p.add_argument("--timeout", type=float, default=1200.0, help="seconds per test run")
    p.add_argument("--skip-baseline", action="store_true",
                   help="do not first run the tests on the unmutated copy (only where they have just passed on it)")
    args = p.parse_args(argv)
    mutations = MUTATIONS[:args.only] if args.only else MUTATIONS
    if args.select:
        mutations = [m for m in mutations if re.search(args.select, f"{m[0]} {m[3]}")]
        if not mutations:
            print(f"mutation_check: no mutation matches --select {args.select!r}", file=sys.stderr)
            return 2
    for file, old, new, what in mutations:  # the table itself must still match the code
        text = (REPO / "toolkit" / "microimpact" / file).read_text()
        if text.count(old) != 1:
            print(f"mutation_check: '{old}' occurs {text.count(old)} times in {file} (must be once): {what}",
                  file=sys.stderr)
            return 2
    results = []
    with tempfile.TemporaryDirectory(prefix="mutation_check_") as tmp:
        tmp = Path(tmp)
        if not args.skip_baseline:
            root = _copy_package(tmp / "baseline")
            status, seconds, last = _run_tests(root, tmp / "baseline" / "numba", args.timeout)
            print(f"baseline: status {status} in {seconds:.0f} s ({last})", flush=True)
            if status != 0:
                print("mutation_check: the unmutated package fails its tests; nothing to check", file=sys.stderr)
                return 2
        for i, (file, old, new, what) in enumerate(mutations, 1):
            work = tmp / f"m{i}"
            root = _copy_package(work)
            target = root / "microimpact" / file
            target.write_text(target.read_text().replace(old, new))
            status, seconds, last = _run_tests(root, work / "numba", args.timeout)
            killed = status != 0
            results.append({"file": file, "what": what, "original": old, "mutation": new, "killed": killed,
                            "seconds": round(seconds, 1), "first_failure": last if killed else None})
            print(f"{i:2d}/{len(mutations)} {'killed' if killed else 'SURVIVED'} in {seconds:4.0f} s: "
                  f"{what} ({file}){': ' + last if killed else ''}", flush=True)
            shutil.rmtree(work, ignore_errors=True)
    survived = [r for r in results if not r["killed"]]
    summary = {"mutations": len(results), "killed": len(results) - len(survived),
               "score": (len(results) - len(survived)) / len(results), "tests": KILLERS, "results": results}
    if args.out:
        args.out.write_text(json.dumps(summary, indent=1) + "\n")
    print(f"mutation_check: {summary['killed']} of {summary['mutations']} mutations killed"
          + (f"; survived: {', '.join(r['what'] for r in survived)}" if survived else ""))
    return 1 if survived else 0


if __name__ == "__main__":
    sys.exit(main())
