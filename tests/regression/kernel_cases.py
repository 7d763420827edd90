"""Bit-for-bit fingerprint of the three compiled adaptive solvers (tests/regression/baseline/kernels.json).

The engine (:func:`microimpact.solvers.engine.solve_normal`), the JKR/DMT/Hertz solver
(:func:`microimpact.solvers.normal_models.solve_normal`) and the coupled solver
(:func:`microimpact.solvers.coupled.solve_coupled`) over impacts drawn from the extended domain
(damping 0 and 1e-5 to 1e6, speeds 1e-6 to 1e3 m/s), each with the options that take their
branches: the captured tail (``need_tail``), the end of sliding (``friction_impulse_target``), the
recorded trajectory and the followed capture of the engine, and every tangential sub-model of the
coupled solver. Every output is kept exactly (``float.hex``), with its step counts, so that a
rewrite of a solver that must not change its arithmetic (a loop split into helpers) can show it
gives the same numbers bit for bit; a solve that raises is kept as the name of its exception.

``python tests/regression/kernel_cases.py`` rewrites the baseline from the current code;
``tests/test_regression.py`` compares. Bit for bit holds on the machine (CPU, numba and LLVM) that
wrote the baseline; elsewhere the tolerance-based baselines of that file apply.
"""

from __future__ import annotations

import hashlib
import json
import math
import warnings
from pathlib import Path

import numpy as np

BASELINE = Path(__file__).parent / "baseline" / "kernels.json"
RTOL = 1e-8
N = 24


def _log_uniform(rng, lo, hi):
    return float(10.0 ** rng.uniform(math.log10(lo), math.log10(hi)))


def cases():
    """N impacts (dicts of SI floats): radius 1e-7-1e-3 m, damping 0 or 1e-5-1e6, speed 1e-6-1e3 m/s."""
    rng = np.random.default_rng(5052)
    out = []
    for _ in range(N):
        zeta = [0.0 if rng.random() < 0.15 else _log_uniform(rng, 1e-5, 1e6) for _ in range(2)]
        out.append({
            "radius": _log_uniform(rng, 1e-7, 1e-3), "density": _log_uniform(rng, 1e3, 2e4),
            "stiffness": _log_uniform(rng, 1e9, 1e11), "work_of_adhesion": _log_uniform(rng, 1e-3, 1.0),
            "zeta_hertz": zeta[0], "zeta_adhesion": zeta[1], "friction": float(rng.uniform(0.05, 1.0)),
            "speed": _log_uniform(rng, 1e-6, 1e3), "incidence_deg": float(rng.uniform(0.0, 85.0)),
            "azimuth_deg": float(rng.uniform(0.0, 360.0)),
            "omega": tuple(float(w) for w in rng.normal(0.0, 1e4, 3)),
        })
    return out


def _contact(case, **fields):
    from microimpact import Contact

    if fields.get("tangential_model", "rigid") != "rigid":
        fields["shear_modulus"] = 0.3 * case["stiffness"]
    return Contact.from_work_of_adhesion(case["radius"], case["density"], case["stiffness"], case["work_of_adhesion"],
                                         zeta_hertz=case["zeta_hertz"], zeta_adhesion=case["zeta_adhesion"],
                                         friction=case["friction"], **fields)


def _dem_contact(case, damping_model):
    """A Hertz contact (no adhesion) under a DEM damping law of zeta_H times the critical damping."""
    from microimpact import Contact
    from microimpact.model.dem_damping import critical_damping_coefficient

    base = Contact(case["radius"], case["density"], case["stiffness"], 0.0, friction=case["friction"],
                   damping_model=damping_model)
    return base.with_(damping_coefficient=case["zeta_hertz"] * critical_damping_coefficient(base, case["speed"]))


def _hex(x) -> str:
    return float(x).hex()


#: The fields of a NormalSolution the baseline holds, in its order (``stop_reason`` and ``state``
#: came later: they say why a solve stopped and hold no number of the kernels)
_SOLUTION_FIELDS = ("outcome", "e_n", "contact_time", "capture_time", "max_penetration", "friction_impulse",
                    "twist_impulse", "dissipated_energy", "final_energy", "slip_end_time", "n_steps", "n_rejected",
                    "time", "penetration", "penetration_rate")


def _solution(s) -> list[str]:
    """Every number of a NormalSolution, exactly; a trajectory as its length and sha256."""
    values = []
    for name, x in ((n, getattr(s, n)) for n in _SOLUTION_FIELDS):
        if isinstance(x, np.ndarray):
            values.append(f"{name}:{x.size}:{hashlib.sha256(np.ascontiguousarray(x).tobytes()).hexdigest()[:16]}")
        elif isinstance(x, str):
            values.append(x)
        elif x is not None:
            values.append(_hex(x))
    return values


def _guarded(solve):
    try:
        return solve()
    except Exception as exc:  # a raised error is part of the fingerprint
        return [type(exc).__name__]


def _engine(case):
    from microimpact.solvers.engine import solve_normal

    c, v = _contact(case), case["speed"]
    j = 0.3 * c.mass * v
    return {
        "plain": _guarded(lambda: _solution(solve_normal(c, v, rtol=RTOL))),
        "tail": _guarded(lambda: _solution(solve_normal(c, v, rtol=RTOL, need_tail=True, friction_impulse_target=j))),
        "recorded": _guarded(lambda: _solution(solve_normal(c, v, rtol=RTOL, trajectory=True, follow_capture=True))),
        "undamped": _guarded(lambda: _solution(solve_normal(c.with_(zeta_hertz=0.0, zeta_adhesion=0.0), v, rtol=RTOL,
                                                            friction_impulse_target=j))),
    }


def _normal_models(case):
    from microimpact.solvers.normal_models import solve_normal

    out = {}
    for model in ("jkr", "jkr_force", "dmt"):
        c, v = _contact(case, normal_model=model), case["speed"]
        j = 0.3 * c.mass * v
        out[model] = _guarded(lambda: _solution(solve_normal(c, v, rtol=RTOL)))
        out[f"{model}-tail"] = _guarded(lambda: _solution(solve_normal(c, v, rtol=RTOL, need_tail=True,
                                                                       friction_impulse_target=j)))
    for damping in ("viscoelastic", "mass_velocity"):
        c = _dem_contact(case, damping)
        out[f"hertz-{damping}"] = _guarded(lambda: _solution(solve_normal(c, case["speed"], rtol=RTOL, need_tail=True)))
    return out


#: (tangential model, friction model, rolling friction) of the coupled solver's selections
COUPLED = (("rigid", "pulloff", 0.0), ("mindlin", "net", 0.0), ("mindlin", "pulloff", 0.01),
           ("mindlin_deresiewicz", "net", 0.0), ("mindlin_deresiewicz", "pulloff", 0.01))


def _coupled(all_cases):
    """Each selection of the coupled solver over all cases, one impact at a time (one contact each)."""
    from microimpact.model.kinematics import incident_velocity
    from microimpact.solvers.coupled import solve_coupled

    out = {}
    for tangential, friction, rolling in COUPLED:
        for i, case in enumerate(all_cases):
            c = _contact(case, tangential_model=tangential, friction_model=friction, rolling_friction=rolling)
            v = incident_velocity(case["speed"], case["incidence_deg"], case["azimuth_deg"])
            w = case["omega"]

            def solve(c=c, v=v, w=w):
                r = solve_coupled(c, tuple(np.array([x]) for x in v), tuple(np.array([x]) for x in w),
                                  np.array([case["friction"]]), rtol=RTOL)
                return [f"{k}:{_hex(np.asarray(r[k], dtype=float)[0])}" for k in sorted(r)]

            out[f"{tangential}-{friction}-{rolling}:{i}"] = _guarded(solve)
    return out


def _batch(solution) -> list[str]:
    """Every array of a batch solve (``solve_normal_many``), exactly."""
    return [f"{k}:" + ",".join(_hex(x) for x in np.asarray(solution[k], dtype=float)) for k in sorted(solution)]


def _many(case):
    """The batch kernels of the engine and the JKR/DMT/Hertz solver (their parallel loops over
    ``_integrate``): each case at its speed and at a tenth of it, the first without, the second with
    the captured tail."""
    from microimpact.solvers import engine, normal_models

    v, tail = np.array([case["speed"], 0.1 * case["speed"]]), np.array([False, True])
    out = {"ring": _guarded(lambda: _batch(engine.solve_normal_many(_contact(case), v, tail, rtol=RTOL)))}
    for model in ("jkr", "dmt"):
        c = _contact(case, normal_model=model)
        out[model] = _guarded(lambda: _batch(normal_models.solve_normal_many(c, v, tail, rtol=RTOL)))
    c = _dem_contact(case, "viscoelastic")
    out["hertz-viscoelastic"] = _guarded(lambda: _batch(normal_models.solve_normal_many(c, v, tail, rtol=RTOL)))
    return out


def fingerprint() -> dict:
    """{solver: {case: [exact outputs]}} of the three solvers over :func:`cases`."""
    all_cases = cases()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # undetermined outcomes and out-of-regime laws: solved all the same
        engine = {f"{i}:{k}": x for i, case in enumerate(all_cases) for k, x in _engine(case).items()}
        normal = {f"{i}:{k}": x for i, case in enumerate(all_cases) for k, x in _normal_models(case).items()}
        many = {f"{i}:{k}": x for i, case in enumerate(all_cases) for k, x in _many(case).items()}
        coupled = _coupled(all_cases)
    return {"engine": engine, "normal_models": normal, "many": many, "coupled": coupled}


def differences(new: dict, old: dict) -> list[str]:
    """The (solver, case) entries of two fingerprints that differ."""
    return [f"{solver}/{key}" for solver in old for key in sorted(set(old[solver]) | set(new.get(solver, {})))
            if new.get(solver, {}).get(key) != old[solver].get(key)]


if __name__ == "__main__":
    BASELINE.write_text(json.dumps(fingerprint(), indent=0, sort_keys=True) + "\n")
    print("wrote", BASELINE)
