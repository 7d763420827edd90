"""CPU time of the compiled normal solvers of two checkouts side by side (for example before and
after a change of the one driver, solvers/driver.py).

Each measurement is one new process importing ``microimpact`` from the given ``toolkit/``
directory, with its own persistent numba cache (so the kernels are compiled once, before the
timing, and not timed). In it ``solve_normal_many`` of one law (the paper's ring law, JKR, DMT)
runs a fixed set of incident speeds at one tolerance, ``--inner`` times; the best process CPU
time (``time.process_time``: the sum over both worker threads, robust to other load on a shared
machine, unlike the wall clock) is printed. The two checkouts alternate ``--alternations`` times
and the best of each is kept; the ratio is second / first::

    python tests/study_driver_speed.py --old OLD/toolkit --new toolkit --alternations 5

Exit status 0; 1 if a measurement fails. Nothing is asserted: timings are not tests.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

#: the laws measured: the preset contact with its normal model replaced
LAWS = {"ring": "C", "jkr": "C.with_(normal_model='jkr')", "dmt": "C.with_(normal_model='dmt')"}
RTOLS = (1e-6, 1e-10)

SCRIPT = """
import sys, time
import numpy as np
from microimpact.presets import WALL_1990 as C
from microimpact.solvers import engine, normal_models
contact = {contact}
solve = engine.solve_normal_many if {law!r} == "ring" else normal_models.solve_normal_many
speeds = np.geomspace(0.05, 20.0, {n})
solve(contact, speeds[:2], rtol={rtol})  # compile or load the kernels, untimed
best = float("inf")
for _ in range({inner}):
    t0 = time.process_time()
    solve(contact, speeds, rtol={rtol})
    best = min(best, time.process_time() - t0)
print(best)
"""


def measure(toolkit: str, cache: str, law: str, rtol: float, n: int, inner: int) -> float:
    """Best CPU time [s] of ``inner`` batch solves in a new process on ``toolkit``."""
    env = dict(os.environ, PYTHONPATH=str(Path(toolkit).resolve()), NUMBA_CACHE_DIR=cache)
    code = SCRIPT.format(contact=LAWS[law], law=law, rtol=rtol, n=n, inner=inner)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    return float(out.stdout.split()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old", required=True, help="the first checkout's toolkit/ directory")
    ap.add_argument("--new", default=str(REPO / "toolkit"), help="the second checkout's toolkit/ directory")
    ap.add_argument("--alternations", type=int, default=5)
    ap.add_argument("--inner", type=int, default=3, help="timed solves per process (best kept)")
    ap.add_argument("--n", type=int, default=2000, help="incident speeds per batch")
    ap.add_argument("--laws", default="ring,jkr,dmt")
    ap.add_argument("--cache", help="a directory for the two numba caches, kept between runs (default: a new one)")
    ap.add_argument("--out", help="write the results as JSON here")
    args = ap.parse_args(argv)
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        scratch = args.cache or tmp
        caches = {"old": os.path.join(scratch, "old"), "new": os.path.join(scratch, "new")}
        for law in args.laws.split(","):
            for rtol in RTOLS:
                best = {"old": float("inf"), "new": float("inf")}
                try:
                    for _ in range(args.alternations):
                        for side in ("old", "new"):
                            t = measure(getattr(args, side), caches[side], law, rtol, args.n, args.inner)
                            best[side] = min(best[side], t)
                except subprocess.CalledProcessError as exc:
                    print(f"{law} rtol={rtol}: measurement failed: {exc.stderr.strip().splitlines()[-1]}",
                          file=sys.stderr)
                    return 1
                row = {"law": law, "rtol": rtol, "old_s": best["old"], "new_s": best["new"],
                       "ratio": best["new"] / best["old"]}
                results.append(row)
                print(f"{law:5s} rtol={rtol:g}: old {best['old']:.4f} s, new {best['new']:.4f} s, "
                      f"new/old {row['ratio']:.3f}", flush=True)
    if args.out:
        Path(args.out).write_text(json.dumps(results, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
