"""Tests of atomic output: microimpact.io.atomic_write, atomic_path, write_csv, write_netcdf."""

from __future__ import annotations

import os
import stat
import subprocess
import sys
import textwrap

import netCDF4
import numpy as np
import pandas as pd
import pytest
import xarray as xr

from microimpact.io import atomic_path, atomic_write, write_csv, write_netcdf, write_netcdf_groups


def leftovers(directory):
    return sorted(p.name for p in directory.iterdir() if p.name.endswith(".tmp"))


def test_atomic_write_text_and_binary(tmp_path):
    target = tmp_path / "out.txt"
    with atomic_write(target) as f:
        f.write("héllo\n")
        assert not target.exists()  # nothing visible until the block succeeds
    assert target.read_text(encoding="utf-8") == "héllo\n"
    with atomic_write(target, "wb") as f:
        f.write(b"\x00\x01")
    assert target.read_bytes() == b"\x00\x01"
    assert leftovers(tmp_path) == []


def test_exception_leaves_old_file_and_no_temp(tmp_path):
    target = tmp_path / "out.txt"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_write(target) as f:
            f.write("half of the new")
            raise RuntimeError("interrupted")
    assert target.read_text() == "old"
    assert leftovers(tmp_path) == []


def test_exception_on_new_file_creates_nothing(tmp_path):
    with pytest.raises(KeyboardInterrupt):
        with atomic_write(tmp_path / "new.txt") as f:
            f.write("x")
            raise KeyboardInterrupt
    assert list(tmp_path.iterdir()) == []


def test_killed_process_leaves_old_file_intact(tmp_path):
    """A process killed mid-write (os._exit, no cleanup) cannot leave a half-written target."""
    target = tmp_path / "out.txt"
    target.write_text("old complete content")
    script = textwrap.dedent(f"""
        import os
        from microimpact.io import atomic_write
        with atomic_write({str(target)!r}) as f:
            f.write("partial")
            f.flush()
            os._exit(3)
    """)
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True)
    assert proc.returncode == 3, proc.stderr.decode()
    assert target.read_text() == "old complete content"


def test_permissions_follow_umask_or_existing_file(tmp_path):
    new = tmp_path / "new.txt"
    with atomic_write(new) as f:
        f.write("x")
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(new.stat().st_mode) == 0o666 & ~umask  # not mkstemp's 0600
    old = tmp_path / "old.txt"
    old.write_text("x")
    old.chmod(0o640)
    with atomic_write(old) as f:
        f.write("y")
    assert stat.S_IMODE(old.stat().st_mode) == 0o640


def test_bad_mode_and_missing_directory(tmp_path):
    with pytest.raises(ValueError, match="mode"):
        with atomic_write(tmp_path / "x", "a"):
            pass
    with pytest.raises(FileNotFoundError, match="does not exist"):
        with atomic_write(tmp_path / "no" / "x"):
            pass


def test_atomic_path_requires_a_file(tmp_path):
    with pytest.raises(FileNotFoundError, match="nothing was written"):
        with atomic_path(tmp_path / "x.bin") as tmp:
            tmp.unlink()
    assert list(tmp_path.iterdir()) == []


def test_write_csv_round_trip(tmp_path):
    df = pd.DataFrame({"row": [1, 2], "radius": [3.45e-6, 1.0 / 3.0], "id": ["a", "b,c"]})
    path = write_csv(df, tmp_path / "t.csv")
    pd.testing.assert_frame_equal(pd.read_csv(path), df)
    assert leftovers(tmp_path) == []


def _dataset():
    return xr.Dataset(
        {
            "e_n": (("speed",), np.linspace(0.1, 0.9, 50), {"units": "1", "long_name": "normal restitution"}),
            "captured": (("speed",), np.arange(50) % 2 == 0),
            "label": ((), "x"),
            "scalar": ((), 1.5),
        },
        coords={"speed": ("speed", np.linspace(1, 50, 50), {"units": "m s-1", "long_name": "incident speed v"})},
        attrs={"title": "test"},
    )


def test_write_netcdf_compresses_numeric_variables(tmp_path):
    ds = _dataset()
    path = write_netcdf(ds, tmp_path / "r.nc")
    with netCDF4.Dataset(path) as nc:
        assert nc.variables["e_n"].filters()["zlib"] is True
        assert nc.variables["speed"].filters()["zlib"] is True
        assert nc.variables["e_n"].units == "1"
    with xr.open_dataset(path) as back:
        back = back.load()
    # as given, plus the global attributes of a CF file (Conventions, history: test_cf.py)
    assert back.attrs.pop("Conventions") == "CF-1.10" and "write_netcdf" in back.attrs.pop("history")
    xr.testing.assert_identical(back, ds)
    assert leftovers(tmp_path) == []


def test_write_netcdf_rewrites_a_dataset_read_from_netcdf(tmp_path):
    first = write_netcdf(_dataset(), tmp_path / "a.nc")
    with xr.open_dataset(first) as ds:
        ds = ds.load()
    write_netcdf(ds.assign(extra=ds.e_n * 2), first)  # overwrite the file it came from
    with xr.open_dataset(first) as back:
        np.testing.assert_allclose(back.extra, ds.e_n * 2)


def test_write_netcdf_groups(tmp_path):
    root = xr.Dataset(attrs={"title": "root", "members": "b a"})
    path = write_netcdf_groups({"b": _dataset(), None: root, "a": _dataset().isel(speed=slice(0, 5))},
                               tmp_path / "g.nc")
    with netCDF4.Dataset(path) as nc:
        assert list(nc.groups) == ["b", "a"] and nc.title == "root"
        assert nc.groups["b"].variables["e_n"].filters()["zlib"] is True
    for name, expected in (("b", _dataset()), ("a", _dataset().isel(speed=slice(0, 5)))):
        with xr.open_dataset(path, group=name) as back:
            xr.testing.assert_identical(back.load(), expected)
    assert leftovers(tmp_path) == []
    with pytest.raises(ValueError, match="no groups"):
        write_netcdf_groups({}, tmp_path / "empty.nc")


def test_write_netcdf_failure_keeps_old_file(tmp_path, monkeypatch):
    path = tmp_path / "r.nc"
    write_netcdf(_dataset(), path)
    before = path.read_bytes()

    def broken(self, target, **kwargs):
        with open(target, "wb") as f:
            f.write(b"CDF half")
        raise OSError("disk full")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", broken)
    with pytest.raises(OSError, match="disk full"):
        write_netcdf(_dataset(), path)
    assert path.read_bytes() == before
    assert leftovers(tmp_path) == []


def test_a_signal_during_a_netcdf_write_lands_after_it_and_abandons_the_file(tmp_path, monkeypatch):
    # SIGINT inside xarray's to_netcdf used to raise under xarray's file lock, and the writer's
    # cleanup then waited for that lock for ever (issue 27); now the write ends, the interrupt is
    # raised after it, and neither the target nor a temporary file is left
    import os
    import signal

    import xarray as xr

    from microimpact.io.files import write_netcdf_groups

    real = xr.Dataset.to_netcdf
    calls = []

    def interrupted(self, *args, **kwargs):
        os.kill(os.getpid(), signal.SIGINT)  # a real signal, delivered while the write is under way
        calls.append("written")
        return real(self, *args, **kwargs)

    monkeypatch.setattr(xr.Dataset, "to_netcdf", interrupted)
    target = tmp_path / "out.nc"
    with pytest.raises(KeyboardInterrupt):
        write_netcdf_groups({None: xr.Dataset({"x": ("t", [1.0, 2.0])}), "g": xr.Dataset({"y": 1.0})}, target)
    assert calls == ["written", "written"]  # both groups were written before the interrupt acted
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_deferred_signals_restores_the_handlers_and_raises_each_signal_once():
    import os
    import signal

    from microimpact._runtime.signals import deferred_signals

    seen = []
    before = signal.signal(signal.SIGTERM, lambda s, f: seen.append(s))
    try:
        with deferred_signals():
            os.kill(os.getpid(), signal.SIGTERM)
            os.kill(os.getpid(), signal.SIGTERM)
            assert seen == []  # held back inside the block
        assert seen == [signal.SIGTERM]
    finally:
        signal.signal(signal.SIGTERM, before)


def test_several_outputs_land_together_or_not_at_all(tmp_path):
    """flags writes CSV and NetCDF: when the second cannot be written the first is not left behind
    (issue 27: fit --posterior once left fit.nc after failing on the posterior)."""
    from microimpact.analysis.flags import write_flags

    ds = xr.Dataset({"row": ("impact", np.array([1, 2])), "e_n": ("impact", [0.5, 0.6])})
    with pytest.raises(FileNotFoundError):
        write_flags(ds, tmp_path / "flags.csv", tmp_path / "missing" / "flags.nc")
    assert sorted(p.name for p in tmp_path.iterdir()) == []
    write_flags(ds, tmp_path / "flags.csv", tmp_path / "flags.nc")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["flags.csv", "flags.nc"]


def test_a_killed_writers_temporary_file_is_removed_by_the_next_write(tmp_path):
    """SIGKILL leaves the hidden temporary file (nothing can run then); the next write of the same
    target removes it, since its writer's process is gone, and leaves a live writer's alone."""
    target = tmp_path / "out.csv"
    script = textwrap.dedent(f"""
        import os, signal
        from microimpact.io.files import atomic_write
        with atomic_write({str(target)!r}) as f:
            f.write("half")
            f.flush()
            os.kill(os.getpid(), signal.SIGKILL)
    """)
    proc = subprocess.run([sys.executable, "-c", script])
    assert proc.returncode == -9
    orphans = list(tmp_path.glob(".out.csv.*.tmp"))
    assert len(orphans) == 1 and not target.exists()
    live = tmp_path / f".out.csv.{os.getpid()}.abc.tmp"  # a writer of this (live) process
    live.write_text("in progress")
    write_csv(pd.DataFrame({"a": [1]}), target)
    assert target.read_text() == "a\n1\n"
    assert sorted(p.name for p in tmp_path.glob(".*.tmp")) == [live.name]


def test_a_signal_between_two_moves_into_place_lands_after_both(tmp_path, monkeypatch):
    """A Ctrl-C while the outputs of one command are moved into place (CI 2026-11-27: ``flags``
    left ``x.csv`` and ``.x.nc.*.tmp`` and said nothing was written): every output lands whole,
    no temporary file is left, the interrupt is raised afterwards, and the process knows which
    files it wrote, so that the CLI can say so."""
    import signal

    from microimpact.io import files

    real = files._fsync_dir
    moved = []

    def signal_after_first_move(directory):
        moved.append(directory)
        if len(moved) == 1:
            os.kill(os.getpid(), signal.SIGINT)  # a real signal, between the first and second move
        return real(directory)

    monkeypatch.setattr(files, "_fsync_dir", signal_after_first_move)
    with pytest.raises(KeyboardInterrupt), files.recorded_outputs() as written:
        with files.all_or_nothing():
            with atomic_write(tmp_path / "a.csv") as f:
                f.write("a")
            with atomic_write(tmp_path / "b.nc") as f:
                f.write("b")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv", "b.nc"]
    assert (tmp_path / "b.nc").read_text() == "b"
    assert written == [tmp_path / "a.csv", tmp_path / "b.nc"]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_an_interrupt_after_the_outputs_are_in_place_is_reported_truthfully(tmp_path, monkeypatch, capsys):
    """The CLI's Ctrl-C line names the outputs it had already moved into place instead of claiming
    that nothing was written."""
    import signal

    from microimpact import cli
    from microimpact.io import files

    real = files._commit

    def commit_then_signal(moves):
        real(moves)
        os.kill(os.getpid(), signal.SIGINT)

    monkeypatch.setattr(files, "_commit", commit_then_signal)
    monkeypatch.chdir(tmp_path)
    status = cli.main(["target", "--e-n", "0.6", "--speed", "2", "--points", "5", "--out", "one.csv"])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 130
    assert err[-1].startswith("microimpact: interrupted after writing one.csv (complete"), err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["one.csv"]
