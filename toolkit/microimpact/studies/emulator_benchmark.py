"""The emulator against the solver, side by side in one run: time per impact and the largest error.

Run ``python -m microimpact.studies.emulator_benchmark [--contacts N] [--impacts M] [--tol TOL]
[--seed S] [--out FILE]``.

What is measured
----------------
* **Contacts.** N random ring-law contacts: radius 0.5-20 um, density 500-5000 kg/m^3, stiffness
  1e8-1e11 Pa, work of adhesion 0.01-1 J/m^2 (log-uniform), with damping chosen so that their
  groups at a reference speed lie at a log-uniform point of the emulator's box
  (:data:`microimpact.solvers.emulator.DOMAIN`; :func:`microimpact.model.reduction.contact_with_groups`,
  the paper's per-impact reference speed). Each has M impacts at speeds 1/3 to 3 times that
  reference speed (log-uniform); the damping groups vary as y0^(-1/5) over them, and the point is
  drawn that much inside the box, so that every impact is inside it (the fallback then solves only
  the guard band about the capture speed; an impact outside the box costs a solve). Some impacts
  are captured.
* **The emulator**: :func:`microimpact.solvers.emulator.restitution` on all N x M impacts at
  ``tol`` (the groups, the table, and the solver for the impacts the table leaves to it); and its
  compiled table alone (:meth:`RingEmulator.evaluate` on the groups). Its build (or load) is timed
  apart.
* **The solver**: :func:`microimpact.solvers.family.normal_restitution` per contact at the default
  rtol (1e-8, the fits' setting), as a fit evaluates its model.
* **The reference**: the same at rtol 1e-12 (e_n errors ~1e-11); the errors of both against it.
* Times with ``time.perf_counter``, the median of ``--repeats`` runs, one thread each (the solvers'
  setting in fits, :func:`microimpact.solvers.engine_threads`), on a warm numba cache. The load
  average before and after is recorded: on a shared machine only ratios measured side by side
  compare.
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

__all__ = ["random_contacts", "run_emulator_benchmark", "main"]

#: rtol of the reference solves [-]
REFERENCE_RTOL = 1e-12
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
    return np.array([normal_restitution(c, v, rtol=rtol, family=False) for c, v in zip(contacts, speeds)])


def run_emulator_benchmark(contacts: int = 1000, impacts: int = 10, tol: float = emulator.DEFAULT_TOLERANCE,
                           seed: int = 1, repeats: int = 3, domain: dict | None = None) -> dict:
    """The measurements of the module docstring, as a JSON-ready dict (``domain``: the table's box,
    default :data:`microimpact.solvers.emulator.DOMAIN`)."""
    domain = dict(emulator.DOMAIN if domain is None else domain)
    load_before = os.getloadavg()
    cs, v = random_contacts(contacts, impacts, seed, domain)
    t0 = time.perf_counter()
    table = emulator.ring_emulator(emulator._table_tolerance(tol), domain)
    build = time.perf_counter() - t0
    with engine_threads(1):
        emulator.restitution(cs[:2], v[:2], tol=tol, domain=domain)  # warm: the kernels compiled or loaded
        _solver(cs[:2], v[:2], DEFAULT_RTOL)
        t_emu, r = _timed(lambda: emulator.restitution(cs, v, tol=tol, domain=domain), repeats)
        y0, c1, c2 = reduction.ring_groups(cs, v)
        t_table, (e_table, _, solve_table) = _timed(lambda: table.evaluate(y0, c1, c2, tol), repeats)
        t_solver, e_solver = _timed(lambda: _solver(cs, v, DEFAULT_RTOL), repeats)
        e_ref = _solver(cs, v, REFERENCE_RTOL)
    n = v.size
    decided = ~r.solved
    return {
        "command": "python -m microimpact.studies.emulator_benchmark " + " ".join(sys.argv[1:]),
        "machine": {"platform": platform.platform(), "python": platform.python_version(), "cpus": os.cpu_count(),
                    "load_average_before": load_before, "load_average_after": os.getloadavg()},
        "contacts": contacts, "impacts_per_contact": impacts, "impacts": n, "tol": tol, "seed": seed,
        "repeats": repeats, "solver_rtol": DEFAULT_RTOL, "reference_rtol": REFERENCE_RTOL,
        "domain": {k: list(x) for k, x in domain.items()},
        "table": {"tolerance": table.tolerance, "build_or_load_s": build, "build_solves": table.n_solves,
                  "max_check_error": table.max_check_error, "cells": int(table.arrays["cell_state"].size),
                  "pieces": int(table.arrays["piece_state"].size)},
        "time_per_impact_s": {"emulator": t_emu / n, "table_kernel": t_table / n, "solver": t_solver / n},
        "speed_ratio_solver_over_emulator": t_solver / t_emu,
        "speed_ratio_solver_over_table_kernel": t_solver / t_table,
        "fraction_solved_by_emulator_fallback": float(r.solved.mean()),
        "max_error_e_n": {"emulator": float(np.max(np.abs(r.e_n - e_ref))),
                          "emulator_table_decided": float(np.max(np.abs(r.e_n[decided] - e_ref[decided]), initial=0.0)),
                          "solver": float(np.max(np.abs(e_solver - e_ref)))},
        "outcome_disagreements": {"emulator": int(np.count_nonzero(r.captured != (e_ref == 0.0))),
                                  "solver": int(np.count_nonzero((e_solver == 0.0) != (e_ref == 0.0)))},
        "captured_fraction": float(np.mean(e_ref == 0.0)),
    }


def main(argv=None) -> int:
    """The command line (module docstring); writes the JSON to ``--out`` or prints it."""
    p = argparse.ArgumentParser(prog="python -m microimpact.studies.emulator_benchmark", description=__doc__.splitlines()[0])
    p.add_argument("--contacts", type=int, default=1000)
    p.add_argument("--impacts", type=int, default=10, help="impacts per contact")
    p.add_argument("--tol", type=float, default=emulator.DEFAULT_TOLERANCE)
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--out", type=Path)
    a = p.parse_args(argv)
    if a.contacts < 1 or a.impacts < 1 or a.repeats < 1:
        p.error("--contacts, --impacts and --repeats must be >= 1")
    if not 0.0 < a.tol < 1.0:
        p.error(f"--tol must lie in (0, 1), got {a.tol!r}")
    result = run_emulator_benchmark(a.contacts, a.impacts, a.tol, a.seed, a.repeats)
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
