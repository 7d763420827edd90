"""Stop signals at random moments of ``microimpact workflow``, each followed by a plain rerun.

Issue 55, item 3: SIGINTs (Ctrl-C: to the wrapper's process group) at moments drawn uniformly from
the duration of an uninterrupted run on a warm numba cache (a first run fills the cache and is the
reference; a second, timed run on a fresh copy gives the duration: a cold run is several times
longer, and moments drawn over it mostly fall after a trial's warm run has ended), ``--early`` of
them in its first 10 s (Snakemake's start-up and first job launch), and SIGTERMs, half to the
process group and half to the wrapper's pid alone (``kill PID``). Each trial checks:

- the wrapper ends within ``--max-stop`` seconds of the signal (default 5);
- what it printed after the signal is one line (the wrapper's; or, for a signal before Snakemake
  started, the command line's own interrupted line), and nothing it printed holds a traceback;
- no process is left: nothing in the wrapper's process group, no Snakemake process in the
  directory;
- the same command again completes, and every NetCDF result then holds the values of the
  uninterrupted run, bit for bit (``xarray.Dataset.equals``), every CSV the same bytes.

The run is the tiny configuration of tests/test_workflow.py (``make_copy``) through
``microimpact workflow --configfile``, with ``--targets`` the Snakemake targets of every run (the
whole pipeline without; it takes several minutes a run, so each trial, a run and its resume, takes
that twice). docs/signals.json holds the study of five targets (validation, reproduction table,
Kharaz comparison, paper dynamics, LAMMPS check: start-up, job launches, jobs in numba kernels and
in LAMMPS, and the end of a run in about a minute)::

    python tests/study_signals.py --sigint 30 --early 10 --sigterm 10 --seed 1 --targets \
        results/impacts_validated.csv results/paper/reproduction.csv results/kharaz.nc \
        results/paper/dynamics.nc results/lammps/check.csv --out docs/signals.json

The trials run in a shuffled order and ``--out`` is rewritten after each one, so a study stopped
early leaves a representative subset (``trials`` says how many ran of ``planned``).

Exit status 0 when every trial passed, 1 otherwise.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from test_workflow import make_copy  # noqa: E402

from microimpact._runtime.locks import snakemake_processes_in  # noqa: E402

ENV = dict(os.environ, PYTHONWARNINGS="ignore", MPLBACKEND="Agg")
# the wrapper's line, and the command line's own (a signal before the wrapper started Snakemake)
INTERRUPTED = ("microimpact: workflow interrupted", "microimpact: interrupted")


#: Snakemake targets of every run (empty: the whole pipeline); set from --targets by main
TARGETS: list[str] = []


def _command(run: Path, config: Path) -> list[str]:
    # the targets before --configfile, which takes every word after it as a file
    return [sys.executable, "-m", "microimpact._entry", "workflow", "--directory", str(run), *TARGETS,
            "--cores", "2", "--configfile", str(config)]


def _fresh(root: Path, template: Path, name: str) -> Path:
    run = root / name
    shutil.copytree(template / "data", run / "data")
    return run


def _results(run: Path) -> dict:
    import xarray as xr

    found = {}
    for path in sorted(run.glob("results/**/*")):
        if path.suffix == ".nc":
            with xr.open_dataset(path) as ds:
                # wall-clock timings (the stress sweep's "seconds") are no result: they differ run to run
                found[str(path.relative_to(run))] = ds.drop_vars([v for v in ds.data_vars if "second" in v]).load()
        elif path.suffix == ".csv":
            found[str(path.relative_to(run))] = path.read_bytes()
    return found


def _same(a: dict, b: dict) -> list[str]:
    problems = [f"missing {k}" for k in a if k not in b] + [f"extra {k}" for k in b if k not in a]
    for k in a.keys() & b.keys():
        equal = a[k] == b[k] if isinstance(a[k], bytes) else a[k].equals(b[k])
        if not equal:
            problems.append(f"differs: {k}")
    return problems


def _group_alive(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
        return True
    except ProcessLookupError:
        return False


def trial(root, template, config, reference, number, signum, to_group, moment, max_stop) -> dict:
    run = _fresh(root, template, f"trial{number}")
    proc = subprocess.Popen(_command(run, config), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=ENV,
                            start_new_session=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    chunks: list[bytes] = []
    os.set_blocking(proc.stdout.fileno(), False)

    def drain():
        try:
            while data := proc.stdout.read():
                chunks.append(data)
        except (BlockingIOError, TypeError):
            pass

    start = time.monotonic()
    while time.monotonic() - start < moment and proc.poll() is None:
        drain()
        time.sleep(0.02)
    drain()
    before = b"".join(chunks)
    finished_first = proc.poll() is not None
    sent = time.monotonic()
    if not finished_first:
        (os.killpg if to_group else os.kill)(proc.pid, signum)
    try:
        while proc.poll() is None and time.monotonic() - sent < 60:
            drain()
            time.sleep(0.02)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    stop = time.monotonic() - sent
    time.sleep(0.2)
    drain()
    out = b"".join(chunks).decode(errors="replace")
    after = [line for line in out[len(before.decode(errors="replace")):].splitlines() if line.strip()]
    left = _group_alive(proc.pid) or bool(snakemake_processes_in(run))
    rerun = subprocess.run(_command(run, config), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=ENV,
                           text=True, timeout=1800)
    problems = [] if rerun.returncode == 0 else [f"rerun exit {rerun.returncode}: {rerun.stdout[-500:]}"]
    problems += _same(reference, _results(run))
    if not finished_first:
        if stop > max_stop:
            problems.append(f"stopped after {stop:.1f} s")
        if len(after) != 1 or not after[0].startswith(INTERRUPTED):
            problems.append(f"printed after the signal: {after[:5]}")
    if "Traceback" in out:
        problems.append("a traceback")
    if left:
        problems.append("a process was left")
    shutil.rmtree(run, ignore_errors=True)
    return {"trial": number, "signal": signal.Signals(signum).name, "to": "group" if to_group else "wrapper pid",
            "moment": round(moment, 2), "finished_before_the_signal": finished_first, "stop_seconds": round(stop, 2),
            "status": proc.returncode, "lines_after": len(after), "problems": problems, "passed": not problems}


def _by_kind(rows) -> dict:
    """Count the trials signalled while their run lived, by signal, recipient and (SIGINT) early or late."""
    counts = {}
    for r in rows:
        if r["finished_before_the_signal"]:
            continue
        kind = f'{r["signal"]} to {r["to"]}' + ((" early" if r["moment"] < 10.0 else " late") if r["signal"] == "SIGINT" else "")
        counts[kind] = counts.get(kind, 0) + 1
    return counts


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sigint", type=int, default=30)
    parser.add_argument("--early", type=int, default=10, help="of the SIGINTs, how many in the first 10 s")
    parser.add_argument("--sigterm", type=int, default=10, help="half to the group, half to the wrapper pid")
    parser.add_argument("--max-stop", type=float, default=5.0)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", default=None)
    parser.add_argument("--targets", nargs="*", default=[],
                        help="Snakemake targets (files) of every run; default: the whole pipeline")
    args = parser.parse_args()
    TARGETS[:] = args.targets
    rng = random.Random(args.seed)
    root = Path(tempfile.mkdtemp(prefix="study-signals-"))
    template = make_copy(root / "template")
    config = template / "workflow" / "config" / "config.yaml"
    ref_run = _fresh(root, template, "reference")
    t0 = time.monotonic()
    done = subprocess.run(_command(ref_run, config), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=ENV,
                          text=True, timeout=3600)
    cold = time.monotonic() - t0
    if done.returncode != 0:
        print(done.stdout[-3000:])
        return 1
    reference = _results(ref_run)
    warm_run = _fresh(root, template, "warm")
    t0 = time.monotonic()
    done = subprocess.run(_command(warm_run, config), stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=ENV,
                          text=True, timeout=3600)
    duration = time.monotonic() - t0
    warm_differs = _same(reference, _results(warm_run))
    if done.returncode != 0 or warm_differs:
        print(done.stdout[-3000:], warm_differs)
        return 1
    print(json.dumps({"cold_seconds": round(cold, 1), "warm_seconds": round(duration, 1)}), flush=True)
    plan = [(signal.SIGINT, True, rng.uniform(0.0, 10.0)) for _ in range(args.early)]
    # Moments over the first 90 % of the uninterrupted run, so that a trial whose run is a little
    # faster than the measured one still lives at its moment (a trial that ended first counts as unsignalled).
    within = 0.9 * duration
    plan += [(signal.SIGINT, True, rng.uniform(0.0, within)) for _ in range(args.sigint - args.early)]
    plan += [(signal.SIGTERM, i % 2 == 0, rng.uniform(0.0, within)) for i in range(args.sigterm)]
    rng.shuffle(plan)  # any prefix of the trials is a sample of all kinds
    rows = []
    for number, (signum, to_group, moment) in enumerate(plan, 1):
        row = trial(root, template, config, reference, number, signum, to_group, moment, args.max_stop)
        rows.append(row)
        print(json.dumps(row), flush=True)
        summary = {"targets": TARGETS or ["all"], "cold_seconds": round(cold, 1),
                   "uninterrupted_seconds": round(duration, 1),
                   "planned": len(plan), "trials": len(rows), "passed": sum(r["passed"] for r in rows),
                   "signalled": sum(not r["finished_before_the_signal"] for r in rows),
                   "signalled_by_kind": _by_kind(rows), "rows": rows}
        if args.out:
            Path(args.out).write_text(json.dumps(summary, indent=1) + "\n")
    print(json.dumps({k: v for k, v in summary.items() if k != "rows"}))
    shutil.rmtree(root, ignore_errors=True)
    return 0 if summary["passed"] == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main())
