"""Progress bars of the sweeps and the benchmark (issue 13, part 6): drawn on stderr when it is a
terminal, absent when it is a pipe or a file, and without effect on the results.

The terminal case runs the real command under a pseudo-terminal (``pty``); the pipe case runs it
with stderr captured by a pipe.
"""

from __future__ import annotations

import io
import os
import subprocess
import sys

import numpy as np
import pytest

from microimpact._runtime.progress import progress_bar
from microimpact.presets import WALL_1990
from microimpact.studies import sweeps
from microimpact.studies.benchmark.run import _STAGES
from microimpact.studies.sweeps import case_spec, run_sweep

pty = pytest.importorskip("pty", reason="pseudo-terminals are POSIX only")

SWEEP = ["sweep", "--case", "2.1"]


def _run_cli(args, tmp_path, *, terminal: bool) -> tuple[int, str]:
    """``microimpact ARGS`` in a subprocess; stderr to a pseudo-terminal or a pipe. (status, stderr)."""
    cmd = [sys.executable, "-m", "microimpact", *args]
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    if not terminal:
        proc = subprocess.run(cmd, cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True, timeout=600)
        return proc.returncode, proc.stderr
    master, slave = pty.openpty()
    proc = subprocess.Popen(cmd, cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=slave)
    os.close(slave)
    chunks = []
    while True:
        try:
            data = os.read(master, 4096)
        except OSError:  # EIO: the child closed the terminal
            break
        if not data:
            break
        chunks.append(data)
    os.close(master)
    proc.communicate(timeout=600)
    return proc.returncode, b"".join(chunks).decode(errors="replace")


@pytest.mark.slow
def test_sweep_draws_a_bar_on_a_terminal(tmp_path):
    status, err = _run_cli([*SWEEP, "--out", "a.nc"], tmp_path, terminal=True)
    assert status == 0, err
    assert "sweep Table 2 case 2.1" in err and "100% |" in err, err
    assert (tmp_path / "a.nc").is_file()


@pytest.mark.slow
def test_sweep_writes_no_bar_into_a_pipe(tmp_path):
    status, err = _run_cli([*SWEEP, "--out", "a.nc"], tmp_path, terminal=False)
    assert status == 0, err
    assert "%" not in err and "\r" not in err, err


def test_sweep_in_blocks_equals_one_batch(monkeypatch):
    """With a bar the speeds are solved in blocks; every impact is solved on its own, so the values
    are identical (exact equality: the same floating-point operations per impact)."""
    spec = case_spec("2.1", {"speed": list(np.linspace(0.4, 6.0, 7)), "incidence_deg": [0.0, 40.0]})
    one = run_sweep(WALL_1990, spec, case="2.1", capture_speed=False)
    monkeypatch.setattr(sweeps, "wants_progress", lambda progress: True)
    monkeypatch.setattr(sweeps, "PROGRESS_BLOCKS", 3)
    calls = []
    batch = sweeps.simulate_many
    monkeypatch.setattr(sweeps, "simulate_many", lambda *a, **k: calls.append(1) or batch(*a, **k))
    blocks = run_sweep(WALL_1990, spec, case="2.1", capture_speed=False, progress=True)
    assert len(calls) == 3  # solved in blocks indeed
    assert list(blocks.dims) == list(one.dims) and dict(blocks.sizes) == dict(one.sizes)
    for name in one.data_vars:
        np.testing.assert_array_equal(blocks[name].values, one[name].values, err_msg=name)
    np.testing.assert_array_equal(blocks["speed"].values, one["speed"].values)


class _Terminal(io.StringIO):
    def isatty(self):
        return True


class _File(io.StringIO):
    def isatty(self):
        return False


@pytest.mark.parametrize(("stream", "drawn"), [(_Terminal, True), (_File, False)])
def test_progress_bar_only_on_a_terminal(monkeypatch, stream, drawn):
    err = stream()
    monkeypatch.setattr(sys, "stderr", err)
    with progress_bar(4, "work", True) as advance:
        for _ in range(4):
            advance()
    assert ("work  100% |" in err.getvalue()) is drawn, err.getvalue()
    with progress_bar(4, "quiet", False) as advance:  # the caller asked for none
        advance(4)
    assert "quiet" not in err.getvalue()


@pytest.mark.slow
@pytest.mark.parametrize(("stream", "drawn"), [(_Terminal, True), (_File, False)])
def test_benchmark_bar_of_its_stages(monkeypatch, stream, drawn):
    """run_benchmark(progress=True): a bar through all its stages on a terminal, nothing otherwise."""
    from microimpact.studies import benchmark
    from microimpact.studies.benchmark import BenchmarkConfig, ObliqueCase

    cfg = BenchmarkConfig(  # the smallest benchmark that runs every stage (as in test_cf.py)
        quick=True, n_speeds=2, max_speed=50.0, capture_margin=1.05,
        engine_levels=(0,), scipy_levels=(0,), rkg_levels=(0,),
        oblique=(ObliqueCase(5.0, 30.0, 0.0, 0.0, 0.0, 1.0, 0.5),),
        repeats_single=1, repeats_scipy=1, repeats_batch=1, batch_size=10,
        throughput_impacts=100, throughput_repeats=1, memory_sizes=(50, 100), time_limit=5.0,
        reference_rtols=(1e-10, 1e-11), family_size=200, family_oblique=False,
    )
    err = stream()
    monkeypatch.setattr(sys, "stderr", err)
    benchmark.run_benchmark(config=cfg, throughput=False, progress=True)
    stages = f"{_STAGES}/{_STAGES}"  # every stage of the benchmark counted once
    assert ("benchmark  100% |" in err.getvalue() and stages in err.getvalue()) is drawn, err.getvalue()
    if not drawn:
        assert err.getvalue() == ""
