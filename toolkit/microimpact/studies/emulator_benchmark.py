"""The emulator against the solver and scipy's DOP853, side by side in one run: time per impact and the largest error.

Run ``python -m microimpact.studies.emulator_benchmark [--contacts N] [--impacts M] [--tol TOL]
[--sample S] [--dop853-sample D] [--solver-contacts K] [--seed SEED] [--repeats R] [--out FILE]``.

What is measured
----------------
* **Contacts.** N random ring-law contacts: radius 0.5-20 um, density 500-5000 kg/m^3, stiffness
  1e8-1e11 Pa, work of adhesion 0.01-1 J/m^2 (log-uniform), with damping chosen so that their
  groups at a reference speed lie at a log-uniform point of the emulator's box
  (:data:`microimpact.solvers.emulator.DOMAIN`; :func:`microimpact.model.reduction.contact_with_groups`,
  the paper's per-impact reference speed). Each has M impacts at speeds 1/3 to 3 times that
  reference speed (log-uniform); the damping groups vary as y0^(-1/5) over them, and the point is
  drawn that much inside the box, so that every impact is inside it (an impact outside the box
  costs a solve). Some impacts are captured.
* **The emulator**: :func:`microimpact.solvers.emulator.restitution` on all N x M impacts at
  ``tol`` (the groups, the table, and the solver for the impacts the table leaves to it); and its
  compiled table alone (:meth:`RingEmulator.evaluate` on the groups). The impacts it leaves to the
  solver are counted by reason (:meth:`RingEmulator.fallback_reasons`). Its build (or load) is
  timed apart.
* **The solver**: :func:`microimpact.solvers.family.normal_restitution` at the default rtol (1e-8,
  the fits' setting), per contact as a fit evaluates its model, on the first K contacts' impacts.
* **DOP853**: :func:`microimpact.solvers.reference.simulate_reference` (scipy's ``solve_ivp``,
  DOP853), one impact a call, on D random impacts at rtol = atol = 1e-8, 1e-9 and 1e-10; its time
  is that of the loosest of these whose largest e_n error over the D impacts is within ``tol``
  (the cheapest DOP853 at the emulator's error), or of the tightest if none is.
* **The reference**: DOP853 at rtol 1e-12 (atol 1e-13, its default) on S random impacts of the N x M
  (captures included; the D impacts are the first of them). The largest e_n errors of the emulator
  and of the solver against it are over these S, and so are the outcome disagreements.
* Times with ``time.perf_counter``, the median of ``--repeats`` runs (DOP853: one run of D
  impacts, between two timings of the emulator, both reported), one thread each (the solvers' setting in fits, :func:`microimpact.solvers.engine_threads`),
  on a warm numba cache. The ratios are of times measured in this one run; the load average before
  and after is recorded: on a shared machine only ratios measured side by side compare.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

from microimpact.model import reduction
from microimpact.solvers import DEFAULT_RTOL, emulator, engine_threads
from microimpact.solvers.family import normal_restitution
from microimpact.solvers.reference import simulate_reference

__all__ = ["random_contacts", "run_emulator_benchmark", "main"]

#: rtol and atol of the reference (DOP853) solves [-]
REFERENCE_RTOL, REFERENCE_ATOL = 1e-12, 1e-13
#: the rtols (= atol) DOP853 is timed at [-]
DOP853_RTOLS = (1e-8, 1e-9, 1e-10)
#: each contact's speeds span a factor SPREAD either side of its reference speed [-]
SPREAD = 3.0


def random_contacts(n: int, m: int, seed: int, domain: dict | None = None):
    """(contacts, speeds (n, m) [m/s]): n random ring contacts with groups in ``domain`` at a reference
    speed, m speeds each from 1/3 to 3 times it (module docstring)."""
    box = emulator.DOMAIN if domain is None else domain
    rng = np.random.default_rng(seed)
    contacts, speeds = [], []
    for _ in range(n):
        # inside the box by the factor the damping groups move over the speeds (C ~ y0^(-1/5), y0 over 9x)
        groups = {k: float(np.exp(rng.uniform(np.log(box[k][0] * SPREAD**0.2), np.log(box[k][1] / SPREAD**0.2))))
                  for k in ("hertz_damping", "adhesion_damping")}
        groups["incident_speed"] = float(np.exp(rng.uniform(np.log(0.05), np.log(200.0))))
        contact, v = reduction.contact_with_groups(
            "ring", radius=10 ** rng.uniform(np.log10(5e-7), np.log10(2e-5)), density=10 ** rng.uniform(np.log10(500), np.log10(5000)),
            stiffness=10 ** rng.uniform(8, 11), work_of_adhesion=10 ** rng.uniform(-2, 0), **groups)
        contacts.append(contact)
        speeds.append(v * np.exp(rng.uniform(-np.log(SPREAD), np.log(SPREAD), m)))
    return contacts, np.array(speeds)


def _timed(func, repeats):
    """(median seconds, last result) of ``repeats`` calls."""
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = func()
        times.append(time.perf_counter() - t0)
    return float(np.median(times)), out


def _solver(contacts, speeds, rtol):
    return np.array([normal_restitution(c, v, rtol=rtol) for c, v in zip(contacts, speeds)])


def _dop853(contacts, speeds, flat, rtol, atol):
    """(e_n, seconds) of DOP853 at the impacts ``flat`` (indices into speeds.ravel()), one call each."""
    m = speeds.shape[1]
    t0 = time.perf_counter()
    e = np.array([simulate_reference(contacts[k // m], float(speeds.flat[k]), rtol=rtol, atol=atol).e_n for k in flat])
    return e, time.perf_counter() - t0


def _cheapest_dop853(timed, e_ref, tol):
    """DOP853 per impact at each rtol of ``timed`` ({rtol: (e_n, seconds)}), its errors against
    ``e_ref``, and the loosest setting within ``tol`` (or the tightest)."""
    runs = {}
    for rtol, (e, t) in timed.items():
        runs[f"{rtol:g}"] = {"time_per_impact_s": t / e.size, "max_error_e_n": float(np.max(np.abs(e - e_ref))),
                             "outcome_disagreements": int(np.count_nonzero((e == 0.0) != (e_ref == 0.0)))}
    ok = [k for k, r in runs.items() if r["max_error_e_n"] <= tol and r["outcome_disagreements"] == 0]
    chosen = ok[0] if ok else f"{DOP853_RTOLS[-1]:g}"
    return runs, chosen, bool(ok)


def _errors(e, captured, e_ref):
    return {"max_error_e_n": float(np.max(np.abs(e - e_ref), initial=0.0)),
            "outcome_disagreements": int(np.count_nonzero(captured != (e_ref == 0.0)))}


def run_emulator_benchmark(contacts: int = 1000, impacts: int = 10, tol: float = emulator.DEFAULT_TOLERANCE,
                           seed: int = 1, repeats: int = 3, domain: dict | None = None, sample: int = 10_000,
                           dop853_sample: int = 100, solver_contacts: int = 100) -> dict:
    """The measurements of the module docstring, as a JSON-ready dict (``domain``: the table's box,
    default :data:`microimpact.solvers.emulator.DOMAIN`; ``sample``, ``dop853_sample`` and
    ``solver_contacts``: S, D and K there)."""
    domain = dict(emulator.DOMAIN if domain is None else domain)
    load_before = os.getloadavg()
    cs, v = random_contacts(contacts, impacts, seed, domain)
    n = v.size
    flat = np.random.default_rng(seed + 1).choice(n, size=min(sample, n), replace=False)
    d = flat[:min(dop853_sample, flat.size)]
    k = min(solver_contacts, contacts)
    t0 = time.perf_counter()
    table = emulator.ring_emulator(emulator.table_tolerance(tol), domain)
    build = time.perf_counter() - t0
    with engine_threads(1):
        emulator.restitution(cs[:2], v[:2], tol=tol, domain=domain)  # warm: the kernels compiled or loaded
        _solver(cs[:1], v[:1, :2], DEFAULT_RTOL)
        _dop853(cs, v, d[:1], REFERENCE_RTOL, REFERENCE_ATOL)
        t_emu, r = _timed(lambda: emulator.restitution(cs, v, tol=tol, domain=domain), repeats)
        y0, c1, c2 = reduction.ring_groups(cs, v)
        t_table, _ = _timed(lambda: table.evaluate(y0, c1, c2, tol), repeats)
        t_solver, e_solver = _timed(lambda: _solver(cs[:k], v[:k], DEFAULT_RTOL), repeats)
        timed_dop853 = {rtol: _dop853(cs, v, d, rtol, rtol) for rtol in DOP853_RTOLS}  # beside the emulator's times
        t_emu_after, _ = _timed(lambda: emulator.restitution(cs, v, tol=tol, domain=domain), repeats)
        e_ref, t_ref = _dop853(cs, v, flat, REFERENCE_RTOL, REFERENCE_ATOL)
        dop853, chosen, reached = _cheapest_dop853(timed_dop853, e_ref[:d.size], tol)
        e_solver_sample = _solver_at(cs, v, flat, DEFAULT_RTOL)
    t_dop853 = dop853[chosen]["time_per_impact_s"]
    decided = ~r.solved.ravel()[flat]
    e_emu, cap_emu = r.e_n.ravel()[flat], r.captured.ravel()[flat]
    per_impact = {"emulator": t_emu / n, "table_kernel": t_table / n, "solver": t_solver / v[:k].size,
                  "dop853": t_dop853, "dop853_reference": t_ref / flat.size, "emulator_after_dop853": t_emu_after / n}
    return {
        "command": "python -m microimpact.studies.emulator_benchmark " + " ".join(sys.argv[1:]),
        "machine": {"platform": platform.platform(), "python": platform.python_version(), "cpus": os.cpu_count(),
                    "load_average_before": load_before, "load_average_after": os.getloadavg()},
        "contacts": contacts, "impacts_per_contact": impacts, "impacts": n, "tol": tol, "seed": seed,
        "repeats": repeats, "solver_rtol": DEFAULT_RTOL, "solver_impacts_timed": int(v[:k].size),
        "reference": {"method": "DOP853", "rtol": REFERENCE_RTOL, "atol": REFERENCE_ATOL, "sample_impacts": int(flat.size)},
        "domain": {key: list(x) for key, x in domain.items()},
        "table": {"tolerance": table.tolerance, "build_or_load_s": build, "build_solves": table.n_solves,
                  "max_check_error": table.max_check_error, "cells": int(table.arrays["cell_state"].size),
                  "cells_left_to_solver": int(np.count_nonzero(table.arrays["cell_state"] == emulator._SOLVE)),
                  "pieces": int(table.arrays["piece_state"].size),
                  "pieces_left_to_solver": int(np.count_nonzero(table.arrays["piece_state"] == emulator._SOLVE))},
        "time_per_impact_s": per_impact,
        "dop853": {"sample_impacts": int(d.size), "settings": dop853, "chosen_rtol": float(chosen),
                   "chosen_reaches_tol": reached},
        "speed_ratio_dop853_over_emulator": t_dop853 / per_impact["emulator"],
        "speed_ratio_dop853_over_emulator_after_dop853": t_dop853 / per_impact["emulator_after_dop853"],
        "speed_ratio_dop853_over_table_kernel": t_dop853 / per_impact["table_kernel"],
        "speed_ratio_solver_over_emulator": per_impact["solver"] / per_impact["emulator"],
        "speed_ratio_solver_over_table_kernel": per_impact["solver"] / per_impact["table_kernel"],
        "fraction_solved_by_emulator_fallback": float(r.solved.mean()),
        "fallback_impacts_by_reason": table.fallback_reasons(y0, c1, c2, tol),
        "errors_against_reference": {
            "emulator": _errors(e_emu, cap_emu, e_ref),
            "emulator_table_decided": _errors(e_emu[decided], cap_emu[decided], e_ref[decided]),
            "emulator_solver_fallback": _errors(e_emu[~decided], cap_emu[~decided], e_ref[~decided]),
            "solver": _errors(e_solver_sample, e_solver_sample == 0.0, e_ref)},
        "sample_fallback_impacts": int(np.count_nonzero(~decided)),
        "captured_fraction": float(np.mean(e_ref == 0.0)),
    }


def _solver_at(contacts, speeds, flat, rtol):
    """The solver's e_n at the impacts ``flat``, per contact."""
    m = speeds.shape[1]
    e = np.empty(flat.size)
    rows = flat // m
    for i in np.unique(rows):
        here = rows == i
        e[here] = normal_restitution(contacts[i], speeds.flat[flat[here]], rtol=rtol)
    return e


def main(argv=None) -> int:
    """The command line (module docstring); writes the JSON to ``--out`` or prints it."""
    p = argparse.ArgumentParser(prog="python -m microimpact.studies.emulator_benchmark", description=__doc__.splitlines()[0])
    p.add_argument("--contacts", type=int, default=1000)
    p.add_argument("--impacts", type=int, default=10, help="impacts per contact")
    p.add_argument("--tol", type=float, default=emulator.DEFAULT_TOLERANCE)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--sample", type=int, default=10_000, help="impacts judged against the DOP853 reference")
    p.add_argument("--dop853-sample", type=int, default=100, help="impacts DOP853 is timed on")
    p.add_argument("--solver-contacts", type=int, default=100, help="contacts whose impacts the solver is timed on")
    p.add_argument("--out", type=Path)
    a = p.parse_args(argv)
    if min(a.contacts, a.impacts, a.repeats, a.sample, a.dop853_sample, a.solver_contacts) < 1:
        p.error("--contacts, --impacts, --repeats, --sample, --dop853-sample and --solver-contacts must be >= 1")
    if not 0.0 < a.tol < 1.0:
        p.error(f"--tol must lie in (0, 1), got {a.tol!r}")
    result = run_emulator_benchmark(a.contacts, a.impacts, a.tol, a.seed, a.repeats, sample=a.sample,
                                    dop853_sample=a.dop853_sample, solver_contacts=a.solver_contacts)
    text = json.dumps(result, indent=2) + "\n"
    if a.out is None:
        print(text, end="")
    else:
        tmp = a.out.with_suffix(".tmp")
        tmp.write_text(text)
        os.replace(tmp, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
