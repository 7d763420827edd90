"""Compare every result of two pipeline runs value by value: ``python .ci/compare_runs.py A B``.

Used by .ci/run to check that the pipeline run through the SLURM profile (chunked sweeps, every job
a SLURM job in a process of its own) gives the results of a local ``snakemake --cores 2``. Reads
the files with netCDF4, pandas and json directly (not through microimpact), so a reader of the
toolkit cannot hide a difference.

Compared: every NetCDF variable of every group (numbers to ``RTOL``, NaN equal to NaN; text
exactly) and every attribute; CSV tables cell by cell; JSON documents key by key; Markdown text.
Left out: measurements of the machine rather than results (wall times, speed ratios, load, dates,
versions: ``MACHINE``; the quick benchmark, whose time-budgeted cases finish or not with the
load), figures (their values are the NetCDF's), and the sweep chunks, which only the chunked run
has (their gathered sweeps are compared). A file that only one run has is a
difference. Exit status 1 on any difference, with one line each; 0 with a summary line.
"""

from __future__ import annotations

import json
import math
import re
import sys
from pathlib import Path

import netCDF4
import numpy as np
import pandas as pd

#: relative tolerance for numbers: 0, bit for bit. The SLURM run (every job a process of its own, the
#: sweeps in chunks) and the local run gave equal values in CI (largest relative difference 0, 2026-11-28),
#: and so do a run on an empty numba cache and one on the filled cache (tests/study_cold_warm.py,
#: issue 26). A difference is therefore a defect to find, not noise to tolerate.
RTOL = 0.0
#: names (variables, attributes, JSON keys) that measure the machine, not the model
MACHINE = re.compile(r"^(time_per_impact.*|.*seconds|.*elapsed.*|.*_time_at_target|ratio_.*|.*target_ratio.*|machine_.*|date|"
                     r"history|numba_threads|.*_version|engine_diagnostics|sub_model_costs|single_call_target.*|"
                     r"timing_mode|created|date_created)$")
#: left out: the sweep chunks (only the chunked run has them), figures, and the quick benchmark,
#: a measurement of the machine: it gives each scipy case a wall-clock budget, so which cases
#: finish (its ``status`` and ``notes``) depends on the load (a CI run of 2026-11-26 differed there)
SKIP = re.compile(r"(^|/)chunks/|\.(png|pdf|svg)$|^benchmark/")


#: the largest relative difference of any number compared, over the whole comparison
LARGEST = [0.0]


def _note(a, b) -> None:
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = np.abs(a - b) / np.maximum(np.abs(a), np.abs(b))
    rel = rel[np.isfinite(rel)]
    if rel.size:
        LARGEST[0] = max(LARGEST[0], float(rel.max()))


def _close(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape:
        return False
    if a.dtype.kind in "fc" or b.dtype.kind in "fc":
        _note(a.astype(float), b.astype(float))
        return bool(np.allclose(a.astype(float), b.astype(float), rtol=RTOL, atol=0.0, equal_nan=True))
    return bool(np.array_equal(a, b))


def _same_value(a, b) -> bool:
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(MACHINE.match(k) or _same_value(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_same_value(x, y) for x, y in zip(a, b))
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        _note(np.array([a], float), np.array([b], float))
        return (math.isnan(a) and math.isnan(b)) or math.isclose(a, b, rel_tol=RTOL, abs_tol=0.0)
    if isinstance(a, str) and isinstance(b, str):
        return a == b or _same_numbers_in_text(a, b)
    return _close(a, b)


def _same_numbers_in_text(a: str, b: str) -> bool:
    """Texts that differ only in the last digits of numbers printed to more digits than RTOL."""
    number = r"[-+]?\d+\.\d+(?:[eE][-+]?\d+)?"
    if re.sub(number, "#", a) != re.sub(number, "#", b):
        return False
    return all(math.isclose(float(x), float(y), rel_tol=RTOL) for x, y in zip(re.findall(number, a), re.findall(number, b)))


def _netcdf(a: Path, b: Path) -> tuple[list[str], int]:
    problems, count = [], 0

    def walk(ga, gb, where):
        nonlocal count
        if set(ga.variables) != set(gb.variables) or set(ga.groups) != set(gb.groups):
            problems.append(f"{where}: variables or groups differ: {sorted(set(ga.variables) ^ set(gb.variables))}")
        for name in sorted(set(ga.ncattrs()) | set(gb.ncattrs())):
            if not MACHINE.match(name) and not (name in ga.ncattrs() and name in gb.ncattrs()
                                                and _same_value(ga.getncattr(name), gb.getncattr(name))):
                problems.append(f"{where}: attribute {name} differs")
        for name in sorted(set(ga.variables) & set(gb.variables)):
            if MACHINE.match(name):
                continue
            va, vb = ga.variables[name], gb.variables[name]
            va.set_auto_mask(False)
            vb.set_auto_mask(False)
            count += va.size
            if not _close(va[...], vb[...]):
                problems.append(f"{where}{name}: values differ (largest relative difference "
                                f"{_largest_difference(va[...], vb[...])})")
            for att in set(va.ncattrs()) | set(vb.ncattrs()):
                if not (att in va.ncattrs() and att in vb.ncattrs() and _same_value(va.getncattr(att), vb.getncattr(att))):
                    problems.append(f"{where}{name}: attribute {att} differs")
        for name in sorted(set(ga.groups) & set(gb.groups)):
            walk(ga.groups[name], gb.groups[name], f"{where}{name}/")

    with netCDF4.Dataset(a) as da, netCDF4.Dataset(b) as db:
        walk(da, db, "")
    return problems, count


def _largest_difference(a, b) -> str:
    try:
        a, b = np.asarray(a, float), np.asarray(b, float)
    except (TypeError, ValueError):
        return "text"
    if a.shape != b.shape:
        return f"shapes {a.shape} and {b.shape}"
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = np.abs(a - b) / np.maximum(np.abs(a), np.abs(b))
    rel = rel[np.isfinite(rel)]
    return f"{rel.max():.2e}" if rel.size else "NaN pattern"


def compare(a_root: Path, b_root: Path) -> tuple[list[str], int, int]:
    """Differences between the results under two directories, and the number of files and values
    compared (the largest relative difference of any number is then in ``LARGEST``)."""
    files_a = {p.relative_to(a_root).as_posix() for p in a_root.rglob("*") if p.is_file()}
    files_b = {p.relative_to(b_root).as_posix() for p in b_root.rglob("*") if p.is_file()}
    problems = [f"{f}: only in {a_root if f in files_a else b_root}"
                for f in sorted(files_a ^ files_b) if not SKIP.search(f)]
    files = values = 0
    for rel in sorted(files_a & files_b):
        if SKIP.search(rel):
            continue
        a, b = a_root / rel, b_root / rel
        files += 1
        if rel.endswith(".nc"):
            found, n = _netcdf(a, b)
            values += n
            problems += [f"{rel}: {p}" for p in found]
        elif rel.endswith(".csv"):
            ta, tb = pd.read_csv(a), pd.read_csv(b)
            values += ta.size
            if list(ta.columns) != list(tb.columns) or ta.shape != tb.shape:
                problems.append(f"{rel}: columns or shape differ")
                continue
            for col in ta.columns:
                if not _same_value(ta[col].tolist(), tb[col].tolist()):
                    problems.append(f"{rel}: column {col} differs")
        elif rel.endswith(".json"):
            if not _same_value(json.loads(a.read_text()), json.loads(b.read_text())):
                problems.append(f"{rel}: contents differ")
        elif not _same_value(a.read_text(), b.read_text()):
            problems.append(f"{rel}: text differs")
    return problems, files, values


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print(__doc__.splitlines()[0], file=sys.stderr)
        return 2
    a, b = (Path(x) for x in argv)
    problems, files, values = compare(a, b)
    for p in problems:
        print(f"compare_runs: {p}")
    if problems:
        print(f"compare_runs: {len(problems)} differences between {a} and {b}")
        return 1
    print(f"compare_runs: {files} result files, {values} values: {a} and {b} agree (numbers "
          f"{'bit for bit' if RTOL == 0 else f'to {RTOL:g} relative'}; largest relative difference {LARGEST[0]:.2e})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
