"""Signals in every window (issue 55, item 3): the interpreted run's timer never outlives it, and
``microimpact workflow`` passes SIGTERM on and refuses --unlock while a run lives."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from microimpact import _entry
from microimpact._runtime import timeout


class _Replaced(BaseException):
    """os.execve, replaced: the process image would be replaced here."""


@pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="no interval timers on this platform")
@pytest.mark.parametrize("how", ["error", "too slow"])
def test_the_interpreted_runs_timer_is_cancelled_before_the_compiled_run_replaces_the_process(how, monkeypatch):
    # a timer survives execve: if it still runs there, its SIGALRM kills the compiled command
    # (exit 142, "Alarm clock", nothing printed), as every fallback on a cold cache did
    seen = {}

    def execve(path, argv, env):
        seen["timer"] = signal.getitimer(signal.ITIMER_REAL)
        seen["handler"] = signal.getsignal(signal.SIGALRM)
        raise _Replaced

    def failing_cli(argv):
        if how == "too slow":
            _entry._too_slow(signal.SIGALRM, None)
        raise RuntimeError("the interpreted run failed")

    monkeypatch.setenv("NUMBA_DISABLE_JIT", "0")  # restored afterwards; main sets it to 1
    monkeypatch.setattr(sys, "argv", ["microimpact", "simulate", "--speed", "1"])
    monkeypatch.setattr(_entry, "_interpreted", lambda argv: True)
    monkeypatch.setattr("microimpact.cli.main", failing_cli)
    monkeypatch.setattr(os, "execve", execve)
    previous = signal.getsignal(signal.SIGALRM)
    try:
        with pytest.raises(_Replaced):
            _entry.main()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)
    assert seen["timer"] == (0.0, 0.0)
    assert seen["handler"] == signal.SIG_DFL


# a stand-in for Snakemake: starts a job (a grandchild), says their pids, then waits; SIGINT stops
# both (a traceback on stderr, which the wrapper must drop); with "stubborn" it ignores SIGINT
CHILD = """
import os, signal, subprocess, sys, time
if sys.argv[1] == "stubborn":
    signal.signal(signal.SIGINT, signal.SIG_IGN)
job = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
print(os.getpid(), job.pid, flush=True)
time.sleep(60)
"""
WRAPPER = """
import sys
from microimpact._runtime.supervise import run_supervised
status, signum = run_supervised([sys.executable, "-c", sys.argv[1], sys.argv[2]])
print("wrapper", status, signum, flush=True)
"""


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return Path(f"/proc/{pid}/status").exists() and "zombie" not in Path(f"/proc/{pid}/status").read_text()


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs /proc to find the child's jobs")
@pytest.mark.parametrize("child, signum", [("obedient", signal.SIGTERM), ("obedient", signal.SIGINT),
                                           ("stubborn", signal.SIGTERM)])
def test_a_stop_signal_to_the_wrapper_alone_ends_its_child_and_the_childs_jobs_quietly(child, signum):
    # `kill PID` of microimpact workflow left Snakemake running detached (issue 55): the wrapper now
    # passes the signal on as Ctrl-C to the child and everything it started, kills what has not
    # ended STOP_GRACE s later, and drops what the child prints once stopped
    proc = subprocess.Popen([sys.executable, "-c", WRAPPER, CHILD, child], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)))
    try:
        child_pid, job_pid = map(int, proc.stdout.readline().split())
        sent = time.monotonic()
        os.kill(proc.pid, signum)  # the wrapper's pid alone, not its group
        out, err = proc.communicate(timeout=10)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    took = time.monotonic() - sent
    assert took < 5.0
    assert out.split()[:1] == ["wrapper"] and out.split()[2] == str(int(signum)), out
    assert "Traceback" not in err and err == "", err  # the child's KeyboardInterrupt is dropped
    time.sleep(0.1)
    assert not _alive(child_pid) and not _alive(job_pid)


@pytest.mark.skipif(not Path("/proc/self/cwd").exists(), reason="needs /proc to see other processes")
def test_unlock_is_refused_while_a_snakemake_run_lives_in_the_directory(tmp_path, capsys):
    from microimpact.cli import main

    run = tmp_path / "run"
    (run / ".snakemake" / "locks").mkdir(parents=True)
    (run / ".snakemake" / "locks" / "0.input.lock").write_text("")
    # a process that Snakemake's lock check counts: its command line names snakemake, its cwd is the run
    holder = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)", "snakemake"], cwd=run)
    try:
        time.sleep(0.2)
        assert main(["workflow", "--directory", str(run), "--unlock"]) == 2
    finally:
        holder.kill()
        holder.wait()
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"process {holder.pid}" in err[0] and "--unlock" in err[0], err
    assert (run / ".snakemake" / "locks" / "0.input.lock").exists()


def test_a_time_limit_shorter_than_its_own_set_up_leaves_no_timer_behind():
    # --time-budget 5e-324: the alarm fired as the timer was armed, before the block's try, and the
    # limit stayed in force: the timer went on firing every 0.1 s and raised in later, unrelated code
    before = signal.getsignal(signal.SIGALRM)
    raised = 0
    for _ in range(50):
        try:
            with timeout.time_limit(5e-324, "tiny"):
                time.sleep(1e-4)
        except timeout.TimeLimitExceeded:
            raised += 1
    assert raised == 50
    assert timeout._active == [] and signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)
    assert signal.getsignal(signal.SIGALRM) == before
    with timeout.time_limit(5.0, "after"):  # a later limit is not already expired
        time.sleep(0.01)


# a stand-in for Snakemake that ends at once on SIGTERM, leaving its job (which ignores SIGTERM
# and SIGINT) behind: an orphan, nobody's descendant once its parent has gone
ORPHANING = """
import os, signal, subprocess, sys, time
job = subprocess.Popen([sys.executable, "-c", "import signal, time; signal.signal(signal.SIGTERM, signal.SIG_IGN); "
                        "signal.signal(signal.SIGINT, signal.SIG_IGN); print('ready', flush=True); time.sleep(60)"],
                       stdout=subprocess.PIPE, text=True)
job.stdout.readline()
print(os.getpid(), job.pid, flush=True)
time.sleep(60)
"""


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs /proc to find the child's jobs")
def test_a_job_whose_parent_ended_first_on_a_sigterm_to_the_group_is_killed_too():
    # a SIGTERM to the group of microimpact workflow during Snakemake's start-up once left a process
    # running (docs/signals_supplement.json): Snakemake ended at once and its job, an orphan, was
    # no longer among its descendants when the wrapper killed what was left
    proc = subprocess.Popen([sys.executable, "-c", WRAPPER, ORPHANING, "x"], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)))
    try:
        child_pid, job_pid = map(int, proc.stdout.readline().split())
        os.killpg(proc.pid, signal.SIGTERM)  # the group: the child's default SIGTERM ends it at once
        proc.communicate(timeout=10)
        time.sleep(0.1)
        assert not _alive(child_pid)
        assert not _alive(job_pid)
    finally:
        os.killpg(proc.pid, signal.SIGKILL) if _group_alive(proc.pid) else None


# a stand-in for Snakemake that, on a stop signal, starts one more job (which ignores SIGTERM and
# SIGINT) and ends at once: the job is an orphan the wrapper never saw among its descendants (a
# SIGTERM to the group as Snakemake launched its jobs once left such a process, issue 55's study)
LATE_JOB = """
import os, signal, subprocess, sys, time
def stop(signum, frame):
    job = subprocess.Popen([sys.executable, "-c", "import signal, time; signal.signal(signal.SIGTERM, signal.SIG_IGN); "
                            "signal.signal(signal.SIGINT, signal.SIG_IGN); time.sleep(60)"])
    open(sys.argv[1], "w").write(str(job.pid))  # the wrapper drops what a stopped child prints
    os._exit(0)
signal.signal(signal.SIGTERM, stop)
signal.signal(signal.SIGINT, stop)
print(os.getpid(), flush=True)
time.sleep(60)
"""


@pytest.mark.skipif(not Path("/proc/self/task").exists(), reason="needs /proc to find the child's jobs")
def test_a_job_started_as_the_child_ends_on_a_stop_signal_is_killed_too(tmp_path):
    proc = subprocess.Popen([sys.executable, "-c", WRAPPER, LATE_JOB, str(tmp_path / "job")], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            env=dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path)))
    try:
        int(proc.stdout.readline())  # the child is up, its handlers set
        os.killpg(proc.pid, signal.SIGTERM)
        out, _ = proc.communicate(timeout=10)
        job_pid = int((tmp_path / "job").read_text())
        assert out.split() == ["wrapper", "0", str(int(signal.SIGTERM))]
        assert not _group_alive(proc.pid)  # the late job is gone as the wrapper ends, not left running
        assert not _alive(job_pid)
    finally:
        os.killpg(proc.pid, signal.SIGKILL) if _group_alive(proc.pid) else None


def _group_alive(pgid):
    try:
        os.killpg(pgid, 0)
        return True
    except ProcessLookupError:
        return False
