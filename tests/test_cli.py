"""Command line: bad arguments give exit status 2, one stderr line, nothing on stdout."""

from __future__ import annotations

import json
import math
import subprocess
import sys
import time

import pytest
from numba.core import event as numba_event

from microimpact import cli

GOOD = ["simulate", "--speed", "1.0", "--json"]
FIELDS = ["outcome", "e_n", "mu_t", "mu_tp", "K_L", "K_t", "velocity_out", "omega_out", "contact_time",
          "max_penetration", "slip_ended"]

# (argv after "simulate", a word the error line must contain: the option or field at fault)
BAD = [
    ([], "--speed"),  # missing --speed
    (["--speed", "abc"], "--speed"),
    (["--speed", "nan"], "--speed"),
    (["--speed", "inf"], "--speed"),
    (["--speed", "-1"], "speed"),
    (["--speed", "0"], "speed"),
    (["--speed", "1", "--incidence-deg", "90"], "incidence_deg"),
    (["--speed", "1", "--incidence-deg", "-5"], "incidence_deg"),
    (["--speed", "1", "--incidence-deg", "nan"], "--incidence-deg"),
    (["--speed", "1", "--preset", "nosuch"], "preset"),
    (["--speed", "1", "--bogus", "3"], "--bogus"),
    (["--speed", "1", "--poisson", "0.3"], "--poisson"),  # no Poisson option: unknown
    (["--speed", "1", "--radius", "-1e-6"], "radius"),
    (["--speed", "1", "--radius", "0"], "radius"),
    (["--speed", "1", "--density", "-3"], "density"),
    (["--speed", "1", "--stiffness", "x"], "--stiffness"),
    (["--speed", "1", "--friction", "-0.1"], "friction"),
    (["--speed", "1", "--zeta-hertz", "-1"], "zeta_hertz"),
    (["--speed", "1", "--adhesion-line-force", "inf"], "--adhesion-line-force"),
    (["--speed", "1", "--omega-n", "nan"], "--omega-n"),
    (["--speed", "1", "--rtol", "2"], "rtol"),
    (["--speed", "1", "--method", "magic"], "--method"),
]


def run_main(argv, capsys):
    status = cli.main(argv)
    out, err = capsys.readouterr()
    return status, out, err


@pytest.mark.parametrize("argv,word", BAD, ids=[" ".join(a) or "missing-speed" for a, _ in BAD])
def test_bad_arguments(argv, word, capsys):
    status, out, err = run_main(["simulate", *argv], capsys)
    assert status == 2
    assert out == ""
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("microimpact: error:")
    assert word in lines[0]


def test_no_command(capsys):
    status, out, err = run_main([], capsys)
    assert (status, out) == (2, "")
    assert err.startswith("microimpact: error:") and len(err.splitlines()) == 1


def check_json(text):
    d = json.loads(text)
    for name in FIELDS:
        assert name in d, name
    assert d["outcome"] in ("rebound", "capture")
    assert 0.0 <= d["e_n"] <= 1.0
    assert len(d["velocity_out"]) == 3 and len(d["omega_out"]) == 3
    return d


def test_good_run_json(capsys):
    status, out, err = run_main(GOOD, capsys)
    # nothing on stderr but, on a cold numba cache, the one-line compile notice
    assert status == 0 and [ln for ln in err.splitlines() if not ln.startswith("microimpact: compiling")] == []
    d = check_json(out)
    assert d["outcome"] == "capture"  # Wall (1990) preset at 1 m/s is captured (model notes sec. 2)
    assert d["mu_t"] is None  # NaN for a capture becomes null: the output is strict JSON


def test_good_rebound_json(capsys):
    status, out, _ = run_main(["simulate", "--speed", "10", "--incidence-deg", "30", "--omega-t", "1e5", "--json"], capsys)
    assert status == 0
    d = check_json(out)
    assert d["outcome"] == "rebound"
    assert all(math.isfinite(x) for x in d["velocity_out"])


def subprocess_run(args):
    return subprocess.run([sys.executable, "-m", "microimpact", *args], capture_output=True, text=True, timeout=120)


def test_subprocess_good_and_bad():
    good = subprocess_run(GOOD)
    assert good.returncode == 0, good.stderr
    check_json(good.stdout)
    bad = subprocess_run(["simulate", "--speed", "nan"])
    assert bad.returncode == 2 and bad.stdout == ""
    assert bad.stderr.startswith("microimpact: error:") and len(bad.stderr.splitlines()) == 1
    assert "--speed" in bad.stderr


def test_closed_stdout_exits_quietly():
    """`microimpact simulate ... | head` where head has gone: no error line, the SIGPIPE status.
    The read end is closed before the command writes (it still imports), so the write must fail."""
    proc = subprocess.Popen([sys.executable, "-m", "microimpact", *GOOD], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    proc.stdout.close()
    _, err = proc.communicate(timeout=120)
    assert err == "" and proc.returncode == cli.EXIT_BROKEN_PIPE == 141


def test_time_budget_status_and_generous_budget(tmp_path, capsys):
    """--time-budget: exit status 3 when spent (documented in --help); a generous budget runs as
    without one (the values: tests/test_time_budget.py)."""
    assert "3 the computation ran past --time-budget" in " ".join(cli.build_parser().format_help().split())
    assert cli.main(["sweep", "--case", "2.2", "--out", str(tmp_path / "a.nc"), "--time-budget", "1e6"]) == 0
    capsys.readouterr()
    assert cli.main(["sweep", "--case", "2.2", "--out", str(tmp_path / "c.nc"), "--time-budget", "1e-9"]) == 3
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "time budget of 1e-09 s exceeded" in err and "--time-budget" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.nc"]


def _compile_seconds(events) -> float:
    """Wall time [s] spent in numba compiles, from a recorder's (time, event) pairs (nested compiles once)."""
    depth, total, start = 0, 0.0, 0.0
    for when, ev in events:
        if ev.is_start:
            depth += 1
            start = when if depth == 1 else start
        else:
            depth -= 1
            total += (when - start) if depth == 0 else 0.0
    return total


@pytest.mark.extended
def test_benchmark_stops_at_its_time_budget_and_writes_nothing(tmp_path, capsys):
    """benchmark --time-budget (issue 27: the one long command without a budget): a quick benchmark
    takes 30-60 s here; with a 3 s budget it ends in one line with status 3 and --out stays empty.
    numba's compiles are not interrupted (tests/test_time_budget.py: an interrupted compile crashed a
    CI worker), so on a fresh cache the bound is 3 + 10 s beyond the time spent compiling; the 10 s
    allow the longest compiled call on a loaded machine."""
    out = tmp_path / "bench"
    t0 = time.perf_counter()
    with numba_event.install_recorder("numba:compile") as compiles:
        status = cli.main(["benchmark", "--quick", "--no-throughput", "--out", str(out), "--time-budget", "3"])
    elapsed = time.perf_counter() - t0
    assert status == 3
    err = capsys.readouterr().err
    assert "microimpact: error: benchmark: time budget of 3 s exceeded" in err and "--time-budget" in err, err
    assert elapsed - _compile_seconds(compiles.buffer) < 13.0, (elapsed, _compile_seconds(compiles.buffer))
    assert not out.exists() or not any(out.iterdir())


def test_a_budget_spent_inside_a_numba_compile_still_ends_in_its_own_line(tmp_path, monkeypatch, capsys):
    """numba re-raises an exception from inside a compile pass as the same type with the pass on a
    line before the message (seen in CI: "Failed in nopython mode pipeline (step: parfor
    prelowering)"); the command must still end with the budget's one line and status 3."""
    from microimpact._commands import benchmark  # the command's handler, which calls run_benchmark
    from microimpact.solvers import TimeBudgetExceeded

    def compiling_when_the_budget_ran_out(**kwargs):
        raise TimeBudgetExceeded("Failed in nopython mode pipeline (step: parfor prelowering)\n"
                                 "benchmark: time budget of 3 s exceeded")

    monkeypatch.setattr(benchmark, "run_benchmark", compiling_when_the_budget_ran_out)
    out = tmp_path / "bench"
    assert cli.main(["benchmark", "--quick", "--time-budget", "3", "--out", str(out)]) == 3
    err = capsys.readouterr().err
    assert err == ("microimpact: error: benchmark: time budget of 3 s exceeded; give a larger --time-budget, "
                   "or none for no limit\n"), err
    assert not out.exists() or not any(out.iterdir())


#: one impact of each solver family that `simulate` runs interpreted: ring law rebound and capture,
#: the hysteretic tangential law (coupled solver), JKR oblique, LAMMPS's Mindlin law
INTERPRETED_CASES = [
    ["--speed", "2"],
    ["--speed", "0.1"],
    ["--speed", "1", "--incidence-deg", "30", "--tangential-model", "mindlin_deresiewicz", "--shear-modulus", "3e8"],
    ["--speed", "0.5", "--normal-model", "jkr", "--incidence-deg", "45"],
    ["--speed", "1", "--incidence-deg", "20", "--tangential-model", "lammps_mindlin", "--shear-modulus", "3e8",
     "--normal-model", "jkr_force", "--damping-model", "viscoelastic", "--damping-coefficient", "1e-7"],
]


def _simulate_in_a_process(case, **env):
    import os

    environ = {k: v for k, v in os.environ.items() if k not in ("NUMBA_DISABLE_JIT", "MICROIMPACT_COMPILED")} | env
    return subprocess.run([sys.executable, "-m", "microimpact._entry", "simulate", *case, "--json"],
                          capture_output=True, text=True, timeout=300, env=environ)


@pytest.mark.parametrize("case", INTERPRETED_CASES, ids=["rebound", "capture", "hysteretic", "jkr", "lammps"])
def test_the_interpreted_impact_prints_the_compiled_numbers_bit_for_bit(case, capsys):
    # `simulate` runs its impact interpreted (microimpact._entry._interpreted): its JSON, every float
    # printed by repr, must equal the compiled solvers' (this process has numba compiling)
    interpreted = _simulate_in_a_process(case, NUMBA_DISABLE_JIT="1")
    assert interpreted.returncode == 0, interpreted.stderr
    status, compiled, _ = run_main(["simulate", *case, "--json"], capsys)
    assert status == 0 and interpreted.stdout == compiled


def test_an_alarm_due_before_the_command_starts_is_a_restart_not_a_traceback(monkeypatch):
    # the interpreted run's alarm delivered the moment it is armed (a budget shorter than the next
    # bytecode on a loaded machine): main must start the command again compiled, not let the
    # alarm's exception escape (seen once in a suite run: exit 1 with an uncaught _CompileInstead)
    import os
    import signal

    from microimpact import _entry

    restarts = []
    real_setitimer = signal.setitimer

    def arm_and_fire(which, seconds, *interval):
        real_setitimer(which, 0.0)
        if seconds > 0:
            os.kill(os.getpid(), signal.SIGALRM)  # Python runs the handler at the next bytecode

    monkeypatch.setattr(_entry, "_interpreted", lambda argv: True)
    def start_compiled(argv):  # the real one replaces the process (execve) and never returns
        restarts.append(argv)
        raise SystemExit(0)

    monkeypatch.setattr(_entry, "_start_compiled", start_compiled)
    monkeypatch.setattr(signal, "setitimer", arm_and_fire)
    monkeypatch.setattr(sys, "argv", ["microimpact", "simulate", "--speed", "2"])
    monkeypatch.setenv("NUMBA_DISABLE_JIT", "0")  # main sets it; monkeypatch restores it
    previous = signal.getsignal(signal.SIGALRM)
    try:
        with pytest.raises(SystemExit):
            _entry.main()
    finally:
        signal.signal(signal.SIGALRM, previous)
    assert restarts == [["simulate", "--speed", "2"]]


def test_simulate_runs_interpreted_and_starts_again_compiled_past_its_budget(capsys):
    from microimpact._entry import _interpreted

    assert _interpreted(["simulate", "--speed", "2"]) is ("numba" not in sys.modules)  # here numba is imported
    assert not _interpreted(["sweep", "--case", "2.2"])
    case = INTERPRETED_CASES[2]
    status, compiled, _ = run_main(["simulate", *case, "--json"], capsys)
    # a budget of 1 ms runs out while numba imports: the process starts again compiled, prints
    # the same once, and nothing on stderr but numba's compile note (a cold cache)
    again = _simulate_in_a_process(case, MICROIMPACT_INTERPRETED_SECONDS="0.001")
    assert again.returncode == 0 and again.stdout == compiled
    assert all(line.startswith("microimpact: compiling") for line in again.stderr.splitlines()), again.stderr
