"""A signal that Python delivers inside a finaliser still stops the process (microimpact._runtime.joblog)."""

import subprocess
import sys
import textwrap

import pytest

SCRIPT = textwrap.dedent("""
    import os, signal, sys, time
    from microimpact._runtime.joblog import JobTerminated, redeliver_swallowed_signals

    if sys.argv[2] == "hook":
        redeliver_swallowed_signals()

    def terminate(signum, frame):
        raise JobTerminated("SIGTERM")

    signal.signal(signal.SIGTERM, terminate)
    signum = getattr(signal, sys.argv[1])

    class Finaliser:
        def __del__(self):
            os.kill(os.getpid(), signum)
            for _ in range(100000):  # the handler runs between these bytecodes, inside __del__
                pass

    Finaliser()
    try:
        deadline = time.monotonic() + 2
        while time.monotonic() < deadline:
            time.sleep(0.01)
        print("ran on")
    except (KeyboardInterrupt, JobTerminated) as exc:
        print("stopped by", type(exc).__name__)
""")


@pytest.mark.parametrize(("signame", "raised"), [("SIGINT", "KeyboardInterrupt"), ("SIGTERM", "JobTerminated")])
@pytest.mark.parametrize("hook", ["hook", "none"])
def test_a_signal_swallowed_by_a_finaliser_is_delivered_again(signame, raised, hook):
    """Without the hook Python prints "Exception ignored" and the process runs on (the CI failure of
    2026-11-26: a SIGTERMed pipeline job kept working and logged a traceback); with it the process
    stops in its main code, silently. The no-hook case shows that the script really puts the
    signal inside the finaliser, so the hooked case can fail."""
    proc = subprocess.run([sys.executable, "-c", SCRIPT, signame, hook], capture_output=True, text=True,
                          timeout=60)
    if hook == "hook":
        assert proc.stdout.strip() == f"stopped by {raised}", (proc.stdout, proc.stderr)
        assert "Exception ignored" not in proc.stderr and "Traceback" not in proc.stderr, proc.stderr
    else:
        assert proc.stdout.strip() == "ran on", (proc.stdout, proc.stderr)
        assert "Exception ignored" in proc.stderr
