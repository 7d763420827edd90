"""Signals at random moments of a pipeline run, each followed by the README's resume command.

Each trial copies the workflow with the tiny configuration of tests/test_workflow.py, starts
``snakemake --cores 2``, sends the signal to the run's process group (as Ctrl-C in a terminal does)
at a moment drawn uniformly from the duration of an uninterrupted run, and then checks:

- the run ends within ``--max-stop`` seconds of the signal (default 10);
- every file under results/ and reports/ is complete or absent: each NetCDF opens and loads, each
  CSV parses, each PDF has its pages, no temporary file is left;
- no job log holds a traceback (a stopped job writes one line);
- the README's resume command completes the run (``snakemake --unlock`` first after SIGKILL), and
  a dry run afterwards has nothing to do.

``--load N`` keeps N busy processes running during the trials (a loaded machine). The summary
(per trial: moment, seconds to stop, files checked, verdicts) is written as JSON::

    python tests/study_interruptions.py --trials 20 --load 1 --seed 1 --out docs/interruptions.json

Exit status 0 when every trial passed, 1 otherwise.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from test_workflow import SNAKEMAKE, make_copy  # noqa: E402

ENV = dict(os.environ, PYTHONWARNINGS="ignore", MPLBACKEND="Agg")


def _run(root: Path, *args: str, timeout: float = 900) -> subprocess.CompletedProcess:
    return subprocess.run([*SNAKEMAKE, *args], cwd=root, env=ENV, stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, text=True, timeout=timeout)


def check_files(root: Path) -> tuple[int, list[str]]:
    """(number of result files checked, problems): each file complete, no temporary file."""
    import pandas as pd
    import xarray as xr
    from pypdf import PdfReader

    problems, n = [], 0
    for path in sorted([*root.glob("results/**/*"), *root.glob("reports/**/*")]):
        if not path.is_file():
            continue
        n += 1
        try:
            if path.name.startswith(".") and path.name.endswith(".tmp"):
                problems.append(f"temporary file left: {path.relative_to(root)}")
            elif path.suffix == ".nc":
                from microimpact.io.files import read_netcdf_groups

                for ds in read_netcdf_groups(path):
                    ds.load()
                with xr.open_dataset(path) as ds:
                    ds.load()
            elif path.suffix == ".csv":
                pd.read_csv(path, comment="#")
            elif path.suffix == ".pdf":
                assert len(PdfReader(path).pages) > 0
            elif path.suffix == ".json":
                json.loads(path.read_text())
        except Exception as exc:  # noqa: BLE001 - every kind of unreadable file is a finding
            problems.append(f"{path.relative_to(root)}: {type(exc).__name__}: {exc}")
    return n, problems


def trial(root: Path, moment: float, signame: str, max_stop: float) -> dict:
    proc = subprocess.Popen([*SNAKEMAKE, "--cores", "2"], cwd=root, env=ENV, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    time.sleep(moment)
    ended_before = proc.poll() is not None
    sent = time.monotonic()
    if not ended_before:
        os.killpg(proc.pid, getattr(signal, signame))
    try:
        out, _ = proc.communicate(timeout=600)
        stop = time.monotonic() - sent
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, _ = proc.communicate()
        stop = float("inf")
    files, problems = check_files(root)
    tracebacks = [str(p.relative_to(root)) for p in root.glob("logs/**/*.log") if "Traceback" in p.read_text()]
    stopped_jobs = sum("interrupted (" in p.read_text() for p in root.glob("logs/**/*.log"))
    if signame == "SIGKILL":
        _run(root, "--unlock")
    t0 = time.monotonic()
    resumed = _run(root, "--cores", "2", "--rerun-incomplete")
    resume_s = time.monotonic() - t0
    again = _run(root, "-n", "--cores", "2")
    files_after, problems_after = check_files(root)
    result = {
        "moment_s": round(moment, 2), "signal": signame, "ended_before_signal": ended_before,
        "seconds_to_stop": round(stop, 2), "jobs_stopped": stopped_jobs, "files_checked": files,
        "problems": problems, "job_logs_with_traceback": tracebacks,
        "resume_status": resumed.returncode, "resume_s": round(resume_s, 1),
        "nothing_left_to_do": "Nothing to be done" in again.stdout,
        "files_after_resume": files_after, "problems_after_resume": problems_after,
    }
    result["passed"] = bool((ended_before or stop <= max_stop) and not problems and not tracebacks
                            and resumed.returncode == 0 and result["nothing_left_to_do"] and not problems_after)
    if not result["passed"]:  # without this machine's paths (the summary may be committed)
        def relative(text: str) -> str:
            return text.replace(str(root), "<trial>").replace(str(Path(__file__).resolve().parents[1]), "<repo>")

        result["run_output_tail"] = relative(out[-3000:])
        result["resume_output_tail"] = relative(resumed.stdout[-3000:])
    return result


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--trials", type=int, default=20)
    parser.add_argument("--signal", default="SIGINT", choices=["SIGINT", "SIGTERM", "SIGKILL"])
    parser.add_argument("--load", type=int, default=0, help="busy processes kept running meanwhile")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--max-stop", type=float, default=10.0, help="seconds a run may take to stop")
    parser.add_argument("--out", default=None, help="JSON summary")
    args = parser.parse_args(argv)

    import numpy as np

    busy = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(args.load)]
    try:
        with tempfile.TemporaryDirectory() as tmp:
            reference = make_copy(Path(tmp) / "reference")
            t0 = time.monotonic()
            full = _run(reference, "--cores", "2")
            duration = time.monotonic() - t0
            if full.returncode != 0:
                print(full.stdout[-3000:], file=sys.stderr)
                return 1
            rng = np.random.default_rng(args.seed)
            trials = []
            for i in range(args.trials):
                moment = float(rng.uniform(0.0, duration))
                r = trial(make_copy(Path(tmp) / f"trial{i}"), moment, args.signal, args.max_stop)
                trials.append(r)
                print(f"trial {i}: signal at {r['moment_s']} s, stopped in {r['seconds_to_stop']} s, "
                      f"{r['jobs_stopped']} job(s) stopped, {r['files_checked']} files, resumed in {r['resume_s']} s: "
                      f"{'pass' if r['passed'] else 'FAIL'}", flush=True)
    finally:
        for p in busy:
            p.kill()
            p.wait()
    stops = [t["seconds_to_stop"] for t in trials if not t["ended_before_signal"]]
    summary = {"command": "python tests/study_interruptions.py " + " ".join(argv if argv is not None else sys.argv[1:]),
               "signal": args.signal, "load_processes": args.load, "uninterrupted_run_s": round(duration, 1),
               "trials": len(trials), "passed": sum(t["passed"] for t in trials),
               "max_seconds_to_stop": max(stops, default=None), "median_seconds_to_stop":
                   float(np.median(stops)) if stops else None, "per_trial": trials}
    if args.out:
        Path(args.out).write_text(json.dumps(summary, indent=1) + "\n")
    print(f"{summary['passed']}/{summary['trials']} trials passed; stop within {summary['max_seconds_to_stop']} s "
          f"(median {summary['median_seconds_to_stop']} s); uninterrupted run {summary['uninterrupted_run_s']} s")
    return 0 if summary["passed"] == summary["trials"] else 1


if __name__ == "__main__":
    sys.exit(main())
