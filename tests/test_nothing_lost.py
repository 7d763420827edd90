"""Nothing is lost: inputs are never modified, outputs are all-or-nothing, even when killed."""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from microimpact.io import ImpactDataError, atomic_write, read_impacts, write_csv, write_netcdf

ROOT = Path(__file__).resolve().parents[1]
INPUTS = sorted((ROOT / "tests" / "data").rglob("*.csv")) + sorted((ROOT / "data").glob("*.csv"))


def sha(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def leftovers(directory):
    return sorted(p.name for p in Path(directory).iterdir() if p.name.endswith(".tmp"))


@pytest.mark.parametrize("path", INPUTS, ids=[str(p.relative_to(ROOT)) for p in INPUTS])
def test_read_impacts_never_modifies_its_input(path):
    before, mtime = sha(path), path.stat().st_mtime_ns
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            read_impacts(path)
        except ImpactDataError:
            pass  # bad files are expected to be rejected; they must still be untouched
    assert sha(path) == before
    assert path.stat().st_mtime_ns == mtime
    assert leftovers(path.parent) == []


def test_inputs_found():
    assert len(INPUTS) >= 3


def test_atomic_write_raise_midway_keeps_old(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old complete\n")
    with pytest.raises(RuntimeError):
        with atomic_write(target) as f:
            f.write("half of the n")
            f.flush()
            raise RuntimeError("writer failed")
    assert target.read_text() == "old complete\n"
    assert leftovers(tmp_path) == []


class Exploding:
    def __init__(self, ok):
        self.ok = ok

    def __str__(self):
        if not self.ok:
            raise RuntimeError("cannot format")
        return "fine"


def test_write_csv_raise_midway_keeps_old(tmp_path):
    target = tmp_path / "table.csv"
    write_csv(pd.DataFrame({"a": [1, 2]}), target)
    before = sha(target)
    df = pd.DataFrame({"a": np.arange(5000), "b": [Exploding(i < 4000) for i in range(5000)]})
    with pytest.raises(RuntimeError):
        write_csv(df, target)
    assert sha(target) == before
    assert leftovers(tmp_path) == []


def test_write_csv_raise_midway_new_file(tmp_path):
    df = pd.DataFrame({"b": [Exploding(i < 10) for i in range(20)]})
    with pytest.raises(RuntimeError):
        write_csv(df, tmp_path / "new.csv")
    assert list(tmp_path.iterdir()) == []


def test_write_netcdf_raise_midway_keeps_old(tmp_path, monkeypatch):
    target = tmp_path / "d.nc"
    ds = xr.Dataset({"x": ("i", np.arange(10.0))})
    write_netcdf(ds, target)
    before = sha(target)

    def half_then_fail(self, path, *args, **kwargs):
        Path(path).write_bytes(b"CDF\x01 partial")
        raise OSError("disk full")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", half_then_fail)
    with pytest.raises(OSError):
        write_netcdf(ds, target)
    assert sha(target) == before
    assert leftovers(tmp_path) == []


WRITER = textwrap.dedent("""
    import os, sys, time
    from microimpact.io import atomic_write
    with atomic_write(sys.argv[1]) as f:
        f.write("first half of the new file\\n")
        f.flush()
        os.fsync(f.fileno())
        print("half", flush=True)
        if sys.argv[2] == "exit":
            os._exit(3)
        time.sleep(60)
        f.write("second half\\n")
""")


@pytest.mark.parametrize("how", ["sigkill", "exit"])
@pytest.mark.parametrize("existing", [True, False])
def test_killed_writer_leaves_no_partial_target(tmp_path, how, existing):
    target = tmp_path / "result.json"
    if existing:
        target.write_text("previous complete content\n")
    proc = subprocess.Popen([sys.executable, "-c", WRITER, str(target), how], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "half"  # the writer is mid-way
        if how == "sigkill":
            os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        proc.stdout.close()
    assert proc.returncode != 0
    if existing:
        assert target.read_text() == "previous complete content\n"
    else:
        assert not target.exists()  # a later run does not take the output as done
    # a hidden temporary may remain after SIGKILL; it is never the target's name
    assert all(p.name.startswith(".result.json.") for p in tmp_path.iterdir() if p != target)


# --------------------------------------------------------------------------- Snakemake's stale lock
@pytest.mark.skipif(not Path("/proc/self/cwd").exists(), reason="needs /proc to see other processes")
def test_a_lock_is_removed_only_when_no_snakemake_process_works_there(tmp_path):
    """A process that names Snakemake and works in the directory holds its lock: nothing is removed
    while it runs; once it is gone the lock is stale and is removed. A process that does not name
    Snakemake (the analyst's shell in that directory) holds nothing."""
    from microimpact._runtime.locks import remove_stale_lock, snakemake_processes_in

    locks = tmp_path / ".snakemake" / "locks"
    locks.mkdir(parents=True)
    for name in ("0.input.lock", "0.output.lock"):
        (locks / name).write_text("results/fit.nc\n")
    sleeper = [sys.executable, "-c", "import time; time.sleep(60)"]
    shell = subprocess.Popen(sleeper, cwd=tmp_path)
    holder = subprocess.Popen([*sleeper, "snakemake"], cwd=tmp_path)  # its command line names Snakemake
    elsewhere = subprocess.Popen([*sleeper, "snakemake", "--directory", str(tmp_path)], cwd="/")
    try:
        assert snakemake_processes_in(tmp_path) == sorted([holder.pid, elsewhere.pid])
        assert remove_stale_lock(tmp_path) == ("held", sorted([holder.pid, elsewhere.pid]))
        assert len(list(locks.glob("*.lock"))) == 2
        for p in (holder, elsewhere):
            p.kill()
            p.wait()
        outcome, removed = remove_stale_lock(tmp_path)
        assert outcome == "unlocked" and len(removed) == 2
        assert not list(locks.glob("*.lock"))
        assert remove_stale_lock(tmp_path) == ("free", [])
    finally:
        for p in (shell, holder, elsewhere):
            p.kill()
            p.wait()
