"""``microimpact fit`` of the bundled 100-row data and of a 100,000-row table of its shape, side by side.

The large table is made by the generator of the bundled data (:func:`microimpact.analysis.synthetic.make_synthetic_impacts`,
its defaults: the same material, the four radii, speeds log-spaced from 1.1 v_c to 100 m/s, the same noise model and
columns) with 25,000 impacts per radius and its own seed. Both files are fitted by the command line, each in its own
subprocess (``python -m microimpact fit FILE --out FIT.nc --json``: what a user runs, start-up and numba's cached
compile included), in pairs, the pair's order alternating; one 100-row fit runs first and is not counted (it fills
numba's cache). Printed and written as JSON: per run the CPU time of the child (user + system, from
``resource.getrusage(RUSAGE_CHILDREN)``) and its wall time, the ratios large / small per pair and their median, and
the fitted values and standard errors of both files::

    python tests/study_large_fit.py --pairs 2 --out docs/large-fit.json

Extra arguments after ``--`` go to both fits (e.g. ``-- --no-confidence-intervals``). With ``--agreement`` the
large table is also fitted in this process by :func:`microimpact.analysis.fitting.fit_damping` with ``method="solve"``
and ``method="emulator"``, and the differences of the estimates and of the 95 % interval ends are written in units of
the solve fit's standard errors, with the bound the emulator fit states (``info["model_evaluation"]``) and each
fit's CPU time.
Exit status 0. Nothing is asserted: timings are not tests (tests/test_large_fit.py holds the tests).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import microimpact
from microimpact.analysis.fitting import fit_damping
from microimpact.analysis.synthetic import write_synthetic_impacts
from microimpact.io import default_materials_path, read_impacts, read_materials

REPO = Path(__file__).resolve().parents[1]
SMALL = REPO / "data" / "synthetic_microspheres.csv"
#: impacts per radius of the large table (four radii: 100,000 rows)
LARGE_PER_RADIUS = 25_000
#: seed of the large table (the bundled data's is 20020101)
LARGE_SEED = 53


def _run_fit(path: Path, out: Path, extra) -> dict:
    """One ``microimpact fit`` in a subprocess: CPU and wall time [s] and the printed JSON."""
    cmd = [sys.executable, "-m", "microimpact", "fit", str(path), "--out", str(out), "--json", *extra]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True, check=False)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed ({proc.returncode}):\n{proc.stderr[-4000:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"cpu_s": cpu, "wall_s": wall, "result": json.loads(proc.stdout)}


def _estimates(result: dict) -> dict:
    """{parameter: {value, stderr, interval}} of the varied parameters of a fit's JSON."""
    out = {}
    for name, p in result["damping"]["parameters"].items():
        if p.get("status") != "fixed":
            out[name] = {k: p.get(k) for k in ("value", "stderr", "interval", "status")}
    return out


def _commit() -> str:
    """The commit of the microimpact imported (and "+dirty" for uncommitted changes)."""
    root = Path(microimpact.__file__).resolve().parents[2]
    run = lambda *a: subprocess.run(["git", "-C", str(root), *a], capture_output=True, text=True).stdout.strip()  # noqa: E731
    return run("rev-parse", "--short", "HEAD") + ("+dirty" if run("status", "--porcelain", "--untracked-files=no") else "")


def _agreement(large: Path) -> dict:
    """The large table fitted in this process by "solve" and by "emulator": differences in standard errors."""
    table = read_impacts(large, materials=default_materials_path())
    material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    fits, cpu = {}, {}
    for method in ("solve", "emulator"):
        t = time.process_time()
        fits[method] = fit_damping(table, material, method=method)
        cpu[method] = time.process_time() - t
    s, e = fits["solve"], fits["emulator"]
    rows = {}
    for name in s.varied:
        se = s.stderr[name]
        a, b = s.identifiability[name], e.identifiability[name]
        rows[name] = {"solve": {"value": s.values[name], "stderr": se, "interval": [a.lower, a.upper]},
                      "emulator": {"value": e.values[name], "stderr": e.stderr[name], "interval": [b.lower, b.upper]},
                      "value_difference_in_stderr": abs(e.values[name] - s.values[name]) / se,
                      "stderr_relative_difference": abs(e.stderr[name] - se) / se,
                      "interval_end_differences_in_stderr": [abs(b.lower - a.lower) / se, abs(b.upper - a.upper) / se]}
    return {"cpu_s": cpu, "parameters": rows, "chisqr": {"solve": s.chisqr, "emulator": e.chisqr},
            "model_evaluation": {"solve": s.info["model_evaluation"], "emulator": e.info["model_evaluation"]}}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=2)
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--large", type=Path, default=None, help="write (or reuse) the large CSV here")
    ap.add_argument("--agreement", action="store_true", help="also fit the large table by both methods in-process")
    ap.add_argument("extra", nargs="*", help="arguments for both fits (after --)")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        large = args.large or tmp / "large.csv"
        if not large.exists():
            write_synthetic_impacts(large, n_per_radius=LARGE_PER_RADIUS, seed=LARGE_SEED)
        _run_fit(SMALL, tmp / "warm.nc", args.extra)  # numba's cache, not counted
        runs = {"small": [], "large": []}
        for k in range(args.pairs):
            order = ("small", "large") if k % 2 == 0 else ("large", "small")
            for which in order:
                runs[which].append(_run_fit(SMALL if which == "small" else large, tmp / f"{which}.nc", args.extra))
        agreement = _agreement(large) if args.agreement else None
    cpu_ratio = [b["cpu_s"] / a["cpu_s"] for a, b in zip(runs["small"], runs["large"])]
    wall_ratio = [b["wall_s"] / a["wall_s"] for a, b in zip(runs["small"], runs["large"])]
    summary = {
        "small": {"data": "data/synthetic_microspheres.csv", "rows": 100},
        "large": {"data": f"make_synthetic_impacts(n_per_radius={LARGE_PER_RADIUS}, seed={LARGE_SEED})",
                  "rows": 4 * LARGE_PER_RADIUS},
        "fit_arguments": args.extra,
        "cpu_s": {w: [r["cpu_s"] for r in rs] for w, rs in runs.items()},
        "wall_s": {w: [r["wall_s"] for r in rs] for w, rs in runs.items()},
        "ratio_cpu": cpu_ratio, "ratio_wall": wall_ratio,
        "median_ratio_cpu": statistics.median(cpu_ratio), "median_ratio_wall": statistics.median(wall_ratio),
        "estimates": {w: _estimates(rs[-1]["result"]) for w, rs in runs.items()},
        "verdict": {w: rs[-1]["result"]["damping"]["verdict"]["verdict_text"] for w, rs in runs.items()},
        "load_average_1min_at_end": os.getloadavg()[0],
        "commit": _commit(),
        "command": "python tests/study_large_fit.py --pairs " + str(args.pairs) + (" --agreement" if args.agreement else "")
                   + (" --out " + str(args.out) if args.out else "") + (" -- " + " ".join(args.extra) if args.extra else ""),
    }
    if agreement is not None:
        summary["agreement_solve_vs_emulator"] = agreement
    text = json.dumps(summary, indent=1)
    print(text)
    if args.out:
        args.out.write_text(text + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
