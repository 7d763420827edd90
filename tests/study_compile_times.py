"""Compile time of each group of compiled kernels: the first call of a solver in a fresh process
with an empty numba cache (cold) against the same call with the kernels cached (warm).

Each group is one call through the public API that needs that group's kernels (the paper's
engine for one impact and for a batch, its speed family, the JKR/DMT solver, the coupled
tangential solver, the DEM tangential laws, the Runge-Kutta-Gill integrator of the paper). Each
runs in a process of its own with its own new ``NUMBA_CACHE_DIR`` (so kernels two groups share are
compiled in each), timing the call alone (not the imports); then again in a new process with the
cache it filled. Compile time is cold minus warm. With ``--repeats N`` the medians of N such
pairs are given (the machine is shared and noisy)::

    python tests/study_compile_times.py --repeats 1 --out docs/compile-times.json

``--toolkit DIR`` measures another checkout's package (for example an older commit's
``toolkit/``), for before/after comparisons. Exit status 0; 1 if a call fails.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

#: one public call per group of kernels (the groups of issue 26); C is the paper's wall contact
GROUPS = {
    "engine, one impact (ring law, friction, spin)":
        "mi.simulate_impact(C, 2.0, 30.0, omega=(0.0, 0.0, 1e5))",
    "engine, batch of speeds (family=False)":
        "mi.simulate_many(C, speed=np.geomspace(0.5, 5.0, 8), incidence_deg=30.0, family=False)",
    "speed family":
        "mi.simulate_many(C, speed=np.geomspace(0.5, 5.0, 8), incidence_deg=30.0, family=True)",
    "JKR/DMT solver":
        "mi.simulate_impact(C.with_(normal_model='jkr'), 2.0, 30.0)",
    "coupled tangential solver (Mindlin)":
        "mi.simulate_impact(C.with_(tangential_model='mindlin', shear_modulus=1e10), 2.0, 40.0)",
    "DEM tangential law (LAMMPS mindlin)":
        "mi.simulate_impact(C.with_(normal_model='jkr_force', zeta_hertz=0.0, zeta_adhesion=0.0, friction=0.3, "
        "tangential_model='lammps_mindlin', shear_modulus=3e8), 1.0, 40.0)",
    "Runge-Kutta-Gill (the paper's integrator)":
        "mi.simulate_impact(C, 2.0, 20.0, method='rkg')",
}

SCRIPT = """
import sys, time
import numpy as np
import microimpact as mi
from microimpact.presets import WALL_1990 as C
start = time.perf_counter()
{call}
print(time.perf_counter() - start)
"""


def _seconds(call: str, cache: Path, toolkit: Path, threads: int | None) -> float:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache), PYTHONPATH=str(toolkit), PYTHONWARNINGS="ignore")
    env.pop("NUMBA_DISABLE_JIT", None)
    if threads is not None:
        env["NUMBA_NUM_THREADS"] = str(threads)
    done = subprocess.run([sys.executable, "-c", SCRIPT.format(call=call)], env=env, capture_output=True, text=True)
    if done.returncode:
        sys.exit(f"study_compile_times: {call} failed:\n{done.stderr[-2000:]}")
    return float(done.stdout.split()[-1])


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeats", type=int, default=1, help="cold/warm pairs per group (default 1)")
    parser.add_argument("--only", type=int, help="the first N groups only")
    parser.add_argument("--toolkit", type=Path, default=REPO / "toolkit", help="the directory holding the package")
    parser.add_argument("--threads", type=int, help="numba threads of each call (default: numba's, all cores); "
                        "1 as in every pipeline rule")
    parser.add_argument("--out", type=Path, help="write the table as JSON here")
    args = parser.parse_args(argv)
    if args.threads is not None and args.threads < 1:
        parser.error(f"--threads must be at least 1, got {args.threads}")
    if args.repeats < 1:
        parser.error(f"--repeats must be at least 1, got {args.repeats}")
    if args.only is not None and not 1 <= args.only <= len(GROUPS):
        parser.error(f"--only must be 1 to {len(GROUPS)}, got {args.only}")
    rows = {}
    print(f"{'group':48s} {'cold [s]':>9s} {'warm [s]':>9s} {'compile [s]':>11s}")
    with tempfile.TemporaryDirectory(prefix="compile_times_") as tmp:
        for i, (name, call) in enumerate(list(GROUPS.items())[:args.only]):
            cold, warm = [], []
            for r in range(args.repeats):
                cache = Path(tmp) / f"cache{i}_{r}"
                cold.append(_seconds(call, cache, args.toolkit.resolve(), args.threads))
                warm.append(_seconds(call, cache, args.toolkit.resolve(), args.threads))
            c, w = statistics.median(cold), statistics.median(warm)
            rows[name] = {"call": call, "cold_seconds": round(c, 3), "warm_seconds": round(w, 4),
                          "compile_seconds": round(c - w, 3)}
            print(f"{name:48s} {c:9.2f} {w:9.3f} {c - w:11.2f}", flush=True)
    if args.out:
        args.out.parent.mkdir(parents=True, exist_ok=True)
        args.out.write_text(json.dumps({"groups": rows, "repeats": args.repeats, "threads": args.threads,
                                        "machine_cpus": os.cpu_count()},
                                       indent=1) + "\n")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except KeyboardInterrupt:
        sys.exit("study_compile_times: interrupted")
