"""Compiled kernels: a first (compiling) run and a cached run give the same numbers, bit for bit,
and an edit of the compiled sources is never answered from a stale cache (microimpact._numba)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]

#: one impact grid through each compiled solver: the paper's engine, JKR, the coupled solver, the RKG
SCRIPT = """
import sys
import numpy as np
import microimpact as mi
from microimpact.presets import WALL_1990 as C
v = np.geomspace(0.5, 50.0, 300)
parts = [mi.simulate_many(C, speed=v, incidence_deg=30.0, omega=(0.0, 0.0, 1e5), family=False)]
if sys.argv[2] == "all":
    parts += [mi.simulate_many(C.with_(normal_model="jkr"), speed=v, family=False),
              mi.simulate_many(C.with_(tangential_model="mindlin", shear_modulus=1e10), speed=v[::10],
                               incidence_deg=40.0)]
values = [np.nan_to_num(ds[k].values.ravel()) for ds in parts for k in ("e_n", "mu_t", "K_L")]
if sys.argv[2] == "all":
    values.append([mi.simulate_impact(C, s, 20.0, method="rkg").e_n for s in (2.0, 5.0)])
np.save(sys.argv[1], np.concatenate(values))
"""


def _run(package_root: Path, cache: Path, out: Path, solvers: str = "all") -> np.ndarray:
    env = dict(os.environ, PYTHONPATH=str(package_root), NUMBA_CACHE_DIR=str(cache))
    subprocess.run([sys.executable, "-c", SCRIPT, str(out), solvers], check=True, env=env, timeout=600,
                   capture_output=True, text=True)
    return np.load(out)


@pytest.mark.slow
def test_a_cold_and_a_warm_run_are_bitwise_equal(tmp_path):
    """With fastmath the first run (code numba has just compiled) and later runs (code loaded from
    its cache) differed by up to 5e-13 in e_n on such a grid, by 4e-8 in a fit's residuals."""
    cache = tmp_path / "cache"
    cold = _run(REPO / "toolkit", cache, tmp_path / "cold.npy")
    assert any(cache.rglob("*.nbi")), "nothing was cached"
    warm = _run(REPO / "toolkit", cache, tmp_path / "warm.npy")
    assert np.array_equal(cold, warm), f"{np.sum(cold != warm)} of {cold.size} values differ"


@pytest.mark.slow
def test_an_edit_of_the_law_is_never_answered_from_a_stale_cache(tmp_path):
    """The solver kernels inline the law of model/law.py; numba's own cache checks only the
    kernel's file, so an edited law kept its old compiled form. The edit here scales the Hertz term
    of the nondimensional equation of motion (Eq. 33) by 1.1 in a copy of the package, which shares
    the first run's cache directory."""
    root = tmp_path / "toolkit"
    shutil.copytree(REPO / "toolkit" / "microimpact", root / "microimpact",
                    ignore=shutil.ignore_patterns("__pycache__"))
    cache = tmp_path / "cache"
    # the paper's engine only: the edit makes the force inconsistent with the energy that the
    # coupled solver's settle test integrates, and it would not finish
    before = _run(root, cache, tmp_path / "before.npy", "engine")
    law = root / "microimpact" / "model" / "law.py"
    text = law.read_text()
    old = "return a_a * root * (1.0 - c2 * y) - a_h * root3 * (1.0 + c1 * y)"
    assert text.count(old) == 1
    law.write_text(text.replace(old, "return a_a * root * (1.0 - c2 * y) - 1.1 * a_h * root3 * (1.0 + c1 * y)"))
    after = _run(root, cache, tmp_path / "after.npy", "engine")
    assert not np.array_equal(before, after), "the edited law was answered from the old cache"
    dirs = sorted(p.name for p in cache.iterdir())
    assert len(dirs) == 2 and all(d.startswith("microimpact-") for d in dirs), dirs


THREADS_SCRIPT = """
import sys
import numpy as np
import microimpact as mi
from microimpact.presets import WALL_1990 as C
from microimpact.solvers import coupled, engine, family, normal_models, rkg
v = np.geomspace(0.5, 50.0, 200)
parts = [mi.simulate_many(C, speed=v, incidence_deg=30.0, omega=(0.0, 0.0, 1e5), family=False),
         mi.simulate_many(C, speed=v, incidence_deg=30.0, family=True),
         mi.simulate_many(C.with_(normal_model="jkr"), speed=v, family=False),
         mi.simulate_many(C.with_(tangential_model="mindlin", shear_modulus=1e10), speed=v[::10], incidence_deg=40.0)]
values = [np.nan_to_num(ds[k].values.ravel()) for ds in parts for k in ("e_n", "mu_t", "K_L")]
values.append(rkg.rkg_restitution(C, v[::20], 200).e_n)
np.save(sys.argv[1], np.concatenate(values))
kernels = [engine._integrate_many, normal_models._integrate_many, coupled.coupled_many, rkg._rkg_many,
           family._evaluate, family._impacts_kernel, family.normal_speed_range]
print(" ".join(f"{k.__module__}.{k.__name__}:{k._parallel is not None}:{k._serial is not None}" for k in kernels))
"""


@pytest.mark.slow
def test_one_thread_compiles_no_parallel_kernel_and_gives_the_numbers_of_two(tmp_path):
    """A process on one thread (every pipeline rule) runs the plain-loop version of each batch
    kernel and never compiles the parallel one (microimpact._numba.njit_batch); the impacts of a
    batch are independent, so two threads give the same numbers bit for bit."""
    runs = {}
    for threads in (1, 2):
        env = dict(os.environ, PYTHONPATH=str(REPO / "toolkit"), NUMBA_CACHE_DIR=str(tmp_path / f"cache{threads}"),
                   NUMBA_NUM_THREADS=str(threads))
        done = subprocess.run([sys.executable, "-c", THREADS_SCRIPT, str(tmp_path / f"{threads}.npy")], check=True,
                              env=env, timeout=900, capture_output=True, text=True)
        runs[threads] = (np.load(tmp_path / f"{threads}.npy"), dict(
            (name, (par == "True", ser == "True")) for name, par, ser in
            (item.split(":") for item in done.stdout.split())))
    one, two = runs[1][0], runs[2][0]
    assert one.size > 1000
    assert np.array_equal(one, two), f"{np.sum(one != two)} of {one.size} values differ"
    # (parallel compiled, serial compiled) per kernel; family._evaluate is not on these paths
    used = {k for k, v in runs[1][1].items() if any(v)}
    assert used == {k for k, v in runs[2][1].items() if any(v)}
    assert len(used) == 6, runs[1][1]
    assert all(runs[1][1][k] == (False, True) for k in used), runs[1][1]
    assert all(runs[2][1][k] == (True, False) for k in used), runs[2][1]


#: a batch kernel in a module of its own (numba caches only functions that live in a file)
BATCH_MODULE = """
import numba
from microimpact._numba import njit_batch


@njit_batch
def squares(x, out):
    for i in numba.prange(x.shape[0]):
        out[i] = x[i] * x[i]
"""

#: holds the kernel's compile lock until a line arrives on stdin, then compiles it into the cache
HOLDER = """
import sys
import numpy as np
import batchmod
from microimpact._numba import _compile_lock
kernel = batchmod.squares.serial
with _compile_lock(kernel):
    print("held", flush=True)
    sys.stdin.readline()
    kernel.compile(tuple(kernel.typeof_pyval(a) for a in (np.arange(3.0), np.empty(3))))
"""

#: calls the kernel while the holder has the lock; says whether it compiled or loaded it
CALLER = """
import numpy as np
import batchmod
out = np.empty(3)
print("calling", flush=True)
batchmod.squares(np.arange(3.0), out)
stats = batchmod.squares.serial.stats
print(out.tolist(), sum(stats.cache_hits.values()), sum(stats.cache_misses.values()), flush=True)
"""


def test_a_batch_kernel_another_process_is_compiling_is_loaded_not_compiled_again(tmp_path):
    """Two pipeline jobs that start at once on an empty cache (the fit and the benchmark) both
    compiled the engine's batch kernel. The caller here reaches its first call while the holder has
    the kernel's compile lock and has not compiled it yet: it must wait, then load the holder's
    compiled kernel from the cache (a cache hit, no miss) instead of compiling it as well."""
    (tmp_path / "batchmod.py").write_text(BATCH_MODULE)
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tmp_path), str(REPO / "toolkit")]),
               NUMBA_CACHE_DIR=str(tmp_path / "cache"), NUMBA_NUM_THREADS="1")
    env.pop("NUMBA_DISABLE_JIT", None)
    holder = subprocess.Popen([sys.executable, "-c", HOLDER], env=env, cwd=tmp_path, text=True,
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    try:
        assert holder.stdout.readline().strip() == "held"
        caller = subprocess.Popen([sys.executable, "-c", CALLER], env=env, cwd=tmp_path, text=True,
                                  stdout=subprocess.PIPE)
        assert caller.stdout.readline().strip() == "calling"
        try:
            caller.wait(timeout=1.0)  # the caller must not finish while the holder has the lock
        except subprocess.TimeoutExpired:
            pass
        assert caller.poll() is None, "the caller did not wait for the compile lock"
        holder.stdin.write("go\n")
        holder.stdin.flush()
        assert holder.wait(timeout=120) == 0
        line, _ = caller.communicate(timeout=120)
    finally:
        holder.kill()
    assert caller.returncode == 0
    assert line.split("]")[0] + "]" == "[0.0, 1.0, 4.0]"
    hits, misses = (int(n) for n in line.split("]")[1].split())
    assert (hits, misses) == (1, 0), f"the caller compiled the kernel itself (hits {hits}, misses {misses})"
