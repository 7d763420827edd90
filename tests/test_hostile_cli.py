"""Hostile-input suite of the command line (issue 12, parts 1, 2 and 7).

Every case is a dict: ``argv`` (paths relative to a fresh work directory, see :func:`workspace`),
``culprit`` (words of which at least one must be in the error: the option, field, file or column at
fault) and optionally ``readonly`` (the directory ``ro`` is not writable) and ``status`` (3: the
computation ran past its ``--time-budget``; default 2). Each case asserts

* exit status 2 and a first stderr line ``microimpact: error: ...`` naming the culprit, no traceback
  (status 3: one such line, the last, after what the command announced before the work);
* nothing written: the work directory holds the same files (hidden ones included) afterwards, so
  no output, partial output or temporary file exists;
* every input byte-identical by sha256 (the work directory's files and the bundled materials config).

Cases are plain data built from the tables below; add a row to grow the corpus. They run
in-process (``microimpact.cli.main``) and are refused before any work, so the suite is fast; a few
end-to-end cases run the installed entry point in a subprocess. The whole suite is extended (its
hundreds of command runs and Ctrl-Cs in real time): ``pytest -n auto -m extended``.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from microimpact.cli import main

pytestmark = pytest.mark.extended
from microimpact.io.materials import default_materials_path

ROOT = Path(__file__).resolve().parents[1]
BAD_CSV = ROOT / "tests" / "data" / "bad_csv"
BUNDLED_CONFIG = str(default_materials_path())

# --------------------------------------------------------------------------- the corpus
FIT = ["fit", "data.csv"]
FLAGS = ["flags", "data.csv", "--fit", "fit.nc"]

#: bad file outputs for any option that writes one file: (path, words of the reason)
BAD_FILE_OUTPUTS = [
    ("dir", ["directory"]),
    ("dir/", ["slash", "directory"]),
    ("newdir/", ["slash", "directory"]),
    ("nodir/out.x", ["does not exist"]),
    ("nodir/deeper/out.x", ["does not exist"]),
    ("data.csv/out.x", ["not a directory"]),
    ("link_to_dir", ["directory"]),
    ("a" * 300, ["too long"]),
    ("dir/" + "b" * 256 + ".x", ["too long"]),
    ("", ["empty"]),
    ("ro/out.x", ["not writable"]),
    ("x\0y", ["NUL"]),
]

#: bad output directories (benchmark --out, --docs)
BAD_DIR_OUTPUTS = [
    ("data.csv", ["not a directory"]),
    ("data.csv/sub", ["not a directory"]),
    ("ro/sub", ["not writable"]),
    ("ro", ["not writable"]),
    ("c" * 300, ["too long"]),
    ("", ["empty"]),
]

CONTACT_OPTIONS = ["radius", "density", "stiffness", "adhesion-line-force", "zeta-hertz", "zeta-adhesion",
                   "friction", "damping-reference-speed"]
NOT_NUMBERS = ["nan", "inf", "-inf", "abc", "", "1,5", "0x1p3"]
NEGATIVE = ["-1", "-1e-6", "-.5", "-1E+3"]
ZERO_INVALID = ["radius", "density", "stiffness", "damping-reference-speed"]
#: values valid on their own whose derived scales leave the floating-point range
EXTREME = [("stiffness", "1e300"), ("density", "1e-300"), ("radius", "1e300"), ("radius", "1e-300"),
           ("adhesion-line-force", "1e-300")]
BAD_RTOL = ["0", "-1", "1", "2", "nan", "inf", "-1e-8", "abc", "1e-400", "1e-300", "1e-16"]
BAD_SPEED = ["0", "-1", "-1e-6", "1e-300", "1e300", "nan", "inf", "-inf", "abc", "", "1e-200"]
BAD_TIME_BUDGET = ["0", "-1", "-0", "nan", "inf", "-inf", "abc", ""]
#: the commands that take --time-budget, each with its outputs
BUDGETED = [[*FIT, "--out", "f.nc"], [*FLAGS, "--out", "o.csv", "--nc", "o.nc"], ["sweep", "--case", "2.1", "--out", "s.nc"],
            ["reproduce", "--out", "r.md"]]


def _field(option):
    return option.lstrip("-").replace("-", "_")


def _cases():
    cases = []

    def add(argv, culprit, **extra):
        cases.append({"argv": list(argv), "culprit": list(culprit), **extra})

    # ---- part 1, nothing lost: outputs that are inputs, or links to them
    for out in ["data.csv", "./data.csv", "link.csv", "hard.csv", "dir/../data.csv", "link_dir/data.csv"]:
        add([*FIT, "--out", out], ["--out", "data file"])
        add([*FLAGS, "--out", out], ["--out", "data file"])
        add([*FLAGS, "--out", "flags.csv", "--nc", out], ["--nc", "data file"])
    for out in ["fit.nc", "link_fit.nc", "./fit.nc"]:
        add([*FLAGS, "--out", out], ["--out", "--fit"])
        add([*FLAGS, "--out", "flags.csv", "--nc", out], ["--nc", "--fit"])
    for out in ["m.yaml", "link_m.yaml"]:
        add([*FIT, "--config", "m.yaml", "--out", out], ["--out", "--config"])
        add([*FLAGS, "--config", "m.yaml", "--out", out], ["--out", "--config"])
    add([*FIT, "--out", BUNDLED_CONFIG], ["--out", "bundled materials config"])
    add(["fit", "link.csv", "--out", "hard.csv"], ["--out", "data file"])
    # two outputs on one path
    for a, b in [("o.csv", "o.csv"), ("o.csv", "./o.csv"), ("o.csv", "dir/../o.csv"), ("data2.csv", "data2.csv")]:
        add([*FLAGS, "--out", a, "--nc", b], ["--out and --nc"])
    add(["benchmark", "--quick", "--out", "bdir", "--docs", "bdir"], ["--out and --docs"])
    add(["benchmark", "--quick", "--out", "bdir", "--docs", "./bdir"], ["--out and --docs"])
    # unusable output paths, for every command that writes
    for path, why in BAD_FILE_OUTPUTS:
        ro = {"readonly": True} if path.startswith("ro") else {}
        add([*FIT, "--out", path], ["--out"], reason=why, **ro)
        add([*FLAGS, "--out", path], ["--out"], reason=why, **ro)
        add([*FLAGS, "--out", "flags.csv", "--nc", path], ["--nc"], reason=why, **ro)
        add(["sweep", "--case", "2.1", "--out", path], ["--out"], reason=why, **ro)
        add(["reproduce", "--out", path], ["--out"], reason=why, **ro)
    for path, why in BAD_DIR_OUTPUTS:
        ro = {"readonly": True} if path.startswith("ro") else {}
        add(["benchmark", "--quick", "--out", path], ["--out"], reason=why, **ro)
        add(["benchmark", "--quick", "--out", "bdir", "--docs", path], ["--docs"], reason=why, **ro)

    # ---- bad input files
    for path, why in [("missing.csv", "does not exist"), ("dir", "directory"), ("", "empty"),
                      ("link_to_dir", "directory")]:
        add(["fit", path, "--out", "f.nc"], ["data file"], reason=[why])
        add(["flags", path, "--fit", "fit.nc", "--out", "o.csv"], ["data file"], reason=[why])
        add([*FIT, "--config", path or "dir/", "--out", "f.nc"], ["--config"])
        add([*FLAGS, "--config", path or "dir/", "--out", "o.csv"], ["--config"])
        add(["flags", "data.csv", "--fit", path, "--out", "o.csv"], ["--fit"], reason=[why])
    for name in sorted(p.name for p in BAD_CSV.glob("*.csv")):
        if name in ("bom_accepted.csv", "unknown_material_pair.csv"):
            continue  # valid files (a BOM; a pair the default config does not know is checked later)
        add(["fit", f"bad/{name}", "--out", "f.nc"], [name])
        add(["flags", f"bad/{name}", "--fit", "fit.nc", "--out", "o.csv"], [name])
    for name in ["garbage.csv", "nul.csv", "fit.nc", "m.yaml", "zero.csv"]:
        add(["fit", name, "--out", "f.nc"], [name])
        add(["flags", name, "--fit", "fit.nc", "--out", "o.csv"], [name])
    for name in ["garbage.nc", "zero.nc", "data.csv", "notfit.nc", "m.yaml"]:
        add(["flags", "data.csv", "--fit", name, "--out", "o.csv"], ["--fit", name])
    for name in ["bad_syntax.yaml", "list.yaml", "negative.yaml", "data.csv", "zero.yaml"]:
        add([*FIT, "--config", name, "--out", "f.nc"], [name, "config"])
    add([*FIT, "--material-pair", "unobtainium", "--out", "f.nc"], ["unobtainium"])
    add([*FLAGS, "--material-pair", "unobtainium", "--out", "o.csv"], ["unobtainium"])

    # ---- part 2, numbers: contact fields (simulate and sweep), speed, angles, spin, rtol
    for cmd in (["simulate", "--speed", "1"], ["sweep", "--case", "2.1", "--out", "s.nc"]):
        for opt in CONTACT_OPTIONS:
            for value in NOT_NUMBERS[:5] + NEGATIVE[:2]:
                add([*cmd, f"--{opt}", value], [f"--{opt}", _field(opt)])
        for opt in ZERO_INVALID:
            add([*cmd, f"--{opt}", "0"], [_field(opt)])
        for opt, value in EXTREME:
            add([*cmd, f"--{opt}", value], [_field(opt)])
        add([*cmd, "--preset", "nosuch"], ["preset"])
        for value in BAD_RTOL:
            add([*cmd, "--rtol", value], ["--rtol", "rtol"])
    for value in NEGATIVE[2:] + NOT_NUMBERS[5:]:
        add(["simulate", "--speed", "1", "--radius", value], ["--radius", "radius"])
    for value in BAD_SPEED:
        add(["simulate", "--speed", value], ["--speed", "speed"])
    for value in ["90", "-5", "1e300", "nan", "-1e-9", "abc"]:
        add(["simulate", "--speed", "1", "--incidence-deg", value], ["--incidence-deg", "incidence_deg"])
    for opt in ["omega-n", "omega-t", "omega-tp"]:
        for value in ["nan", "inf", "1e300", "-1e300"]:
            add(["simulate", "--speed", "1", "--incidence-deg", "30", f"--{opt}", value], [f"--{opt}", "omega"])
    add(["simulate", "--speed", "1", "--azimuth-deg", "inf"], ["--azimuth-deg"])
    add(["simulate", "--speed", "1", "--method", "magic"], ["--method"])
    add(["simulate"], ["--speed"])
    for value in BAD_RTOL:
        add([*FIT, "--rtol", value, "--out", "f.nc"], ["--rtol"])
        add([*FLAGS, "--rtol", value, "--out", "o.csv"], ["--rtol"])
    for value in ["-1", "nan", "inf", "-1e-6"]:
        add([*FLAGS, "--spin-bound", value, "--out", "o.csv"], ["--spin-bound"])
        add([*FLAGS, "--angle-uncertainty-deg", value, "--out", "o.csv"], ["--angle-uncertainty-deg"])
    add([*FIT, "--weights", "some", "--out", "f.nc"], ["--weights"])
    for case in ["9.9", "", "2.1; rm -rf /"]:
        add(["sweep", "--case", case, "--out", "s.nc"], ["--case"])
    add(["sweep", "--out", "s.nc"], ["--case"])
    add(["sweep", "--case", "2.1"], ["--out"])
    add(["fit", "data.csv"], ["--out"])
    add(["flags", "data.csv", "--out", "o.csv"], ["--fit"])
    add(["reproduce"], ["--out"])
    # ---- time budgets: a bad one is a usage error; a tiny one is spent by the first check (status 3)
    for cmd in BUDGETED:
        for value in BAD_TIME_BUDGET:
            add([*cmd, "--time-budget", value], ["--time-budget"])
        add([*cmd, "--time-budget", "1e-9"], ["--time-budget"], reason=["time budget of 1e-09 s exceeded after"],
            status=3)
    add([*FIT, "--out", "f.nc", "--posterior", "p.nc", "--oblique-out", "b.nc", "--time-budget", "1e-9"],
        ["--time-budget"], status=3)
    add([], ["command"])
    add(["nosuch"], ["nosuch"])
    return cases


CASES = _cases()


def _case_id(case):
    text = " ".join(a if len(a) < 40 else a[:12] + "..." for a in case["argv"]) or "(no arguments)"
    return text.replace("\0", "\\0")


# --------------------------------------------------------------------------- the work directory
@pytest.fixture(scope="session")
def fitted(tmp_path_factory):
    """A real fit file (20 synthetic impacts, no confidence intervals) and its data."""
    d = tmp_path_factory.mktemp("hostile_fit")
    lines = (ROOT / "data" / "synthetic_microspheres.csv").read_text().splitlines()
    data = d / "data.csv"
    data.write_text("\n".join([lines[0]] + lines[1::5]) + "\n")
    assert main(["fit", str(data), "--out", str(d / "fit.nc"), "--no-confidence-intervals"]) == 0
    return data, d / "fit.nc"


@pytest.fixture
def workspace(tmp_path, fitted, monkeypatch):
    """A fresh directory with the inputs (good and hostile), links to them, and directories."""
    data, fit = fitted
    w = tmp_path / "work"
    w.mkdir()
    shutil.copy(data, w / "data.csv")
    shutil.copy(data, w / "data2.csv")
    shutil.copy(fit, w / "fit.nc")
    shutil.copy(BUNDLED_CONFIG, w / "m.yaml")
    shutil.copytree(BAD_CSV, w / "bad")
    (w / "dir").mkdir()
    (w / "ro").mkdir()
    (w / "link.csv").symlink_to("data.csv")
    os.link(w / "data.csv", w / "hard.csv")
    (w / "link_fit.nc").symlink_to("fit.nc")
    (w / "link_m.yaml").symlink_to("m.yaml")
    (w / "link_to_dir").symlink_to("dir")
    (w / "link_dir").symlink_to(".")
    (w / "garbage.csv").write_bytes(bytes(range(256)) * 4)
    (w / "nul.csv").write_bytes(data.read_bytes().replace(b",", b"\0"))
    (w / "zero.csv").write_bytes(b"")
    (w / "garbage.nc").write_bytes(b"CDF\x01" + bytes(range(256)))
    (w / "zero.nc").write_bytes(b"")
    import xarray as xr

    xr.Dataset({"x": ("i", [1.0, 2.0])}).to_netcdf(w / "notfit.nc")
    (w / "bad_syntax.yaml").write_text("pairs: {a: [1, 2\n")
    (w / "list.yaml").write_text("- 1\n- 2\n")
    (w / "negative.yaml").write_text("pairs: {x: {density: -1}}\n")
    (w / "zero.yaml").write_text("")
    monkeypatch.chdir(w)
    return w


def _snapshot(directory: Path) -> dict:
    """Every file and link under ``directory`` (hidden ones too) -> sha256 of its bytes."""
    out = {}
    for p in sorted(directory.rglob("*")):
        rel = str(p.relative_to(directory))
        if p.is_symlink():
            out[rel] = "link -> " + os.readlink(p)
        elif p.is_dir():
            out[rel] = "dir"
        else:
            out[rel] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


def _deny_write(directory: Path, monkeypatch):
    """``directory`` is not writable, also for root (who ignores the mode bits)."""
    directory.chmod(0o555)
    real_access = os.access
    denied = str(directory.resolve())

    def access(path, mode, *args, **kwargs):
        p = os.path.realpath(path)
        if mode & os.W_OK and (p == denied or p.startswith(denied + os.sep)):
            return False
        return real_access(path, mode, *args, **kwargs)

    monkeypatch.setattr(os, "access", access)


# --------------------------------------------------------------------------- the tests
def test_corpus_size():
    assert len(CASES) >= 150


@pytest.mark.parametrize("case", CASES, ids=[_case_id(c) for c in CASES])
def test_hostile_case(case, workspace, monkeypatch, capsys):
    if case.get("readonly"):
        _deny_write(workspace / "ro", monkeypatch)
    bundled = hashlib.sha256(Path(BUNDLED_CONFIG).read_bytes()).hexdigest()
    before = _snapshot(workspace)
    try:
        status = main(case["argv"])
    finally:
        (workspace / "ro").chmod(0o755)
    out, err = capsys.readouterr()
    assert status == case.get("status", 2), (out, err)
    lines = err.splitlines()
    errors = [line for line in lines if line.startswith("microimpact: error: ")]
    assert len(errors) == 1, err
    first = errors[0]
    assert first == (lines[-1] if status == 3 else lines[0]), err
    if status == 3:
        assert out == "", out
    assert "Traceback" not in err and "Traceback" not in out
    assert any(word in err for word in case["culprit"]), err
    for word in case.get("reason", []):
        assert word in first or word in err, err
    assert _snapshot(workspace) == before  # nothing written, no temporary left, inputs untouched
    assert hashlib.sha256(Path(BUNDLED_CONFIG).read_bytes()).hexdigest() == bundled


def test_output_error_after_the_work_is_named(workspace, monkeypatch, capsys):
    """An OSError while writing (disk full) is one clean line naming the output; nothing is left."""
    import xarray as xr

    def full(self, path, *args, **kwargs):
        Path(path).write_bytes(b"CDF\x01 partial")
        raise OSError(28, "No space left on device", str(path))

    monkeypatch.setattr(xr.Dataset, "to_netcdf", full)
    before = _snapshot(workspace)
    status = main(["sweep", "--case", "2.1", "--out", "s.nc"])
    err = capsys.readouterr().err
    assert status == 2
    assert err.startswith("microimpact: error: --out 's.nc': cannot write: No space left on device"), err
    assert len(err.splitlines()) == 1
    assert _snapshot(workspace) == before


def test_negative_numbers_are_values(capsys):
    """``--omega-n -5e2`` is a value (argparse alone takes it for an option)."""
    assert main(["simulate", "--speed", "1", "--omega-n", "-5e2", "--omega-t", "-.5", "--json"]) == 0
    assert '"omega_in"' in capsys.readouterr().out


END_TO_END = [
    (["fit", "data.csv", "--out", "data.csv"], "--out 'data.csv': is the input data file"),
    (["flags", "data.csv", "--fit", "fit.nc", "--out", "x.csv", "--nc", "x.csv"], "--out and --nc"),
    (["simulate", "--speed", "1", "--radius", "-1e-6"], "radius must be a finite number > 0"),
    (["simulate", "--speed", "1e-300"], "speed=1e-300"),
    (["simulate", "--speed", "1", "--stiffness", "1e300"], "stiffness=1e+300"),
    (["simulate", "--speed", "1", "--rtol", "0"], "rtol"),
    (["sweep", "--case", "2.1", "--out", "newdir/"], "slash"),
    # issue 27: the posterior a flags run reads is an input like the others
    (["flags", "data.csv", "--fit", "fit.nc", "--out", "x.csv", "--nc", "notfit.nc", "--posterior", "notfit.nc"],
     "--nc 'notfit.nc': is the input --posterior"),
    # a file of the wrong kind is refused, not read as 'no posterior'
    (["flags", "data.csv", "--fit", "fit.nc", "--out", "x.csv", "--posterior", "fit.nc"], "not a posterior (the file that 'microimpact fit --posterior' writes): it is a NetCDF file titled 'damping fit"),
    # an output the file system refuses (root passes os.access everywhere) is refused before the fit runs
    (["fit", "data.csv", "--out", "f.nc", "--posterior", "/sys/p.nc"], "--posterior '/sys/p.nc'"),
    (["benchmark", "--quick", "--out", "/sys/bench"], "--out '/sys/bench': cannot create"),
    # memory bounded before any work, naming the options and the estimate
    (["fit", "data.csv", "--out", "f.nc", "--posterior", "p.nc", "--walkers", "1000000000"],
     "--walkers/--steps/--max-steps: a chain of 1000000000 walkers"),
    (["fit", "data.csv", "--out", "f.nc", "--posterior", "p.nc", "--steps", "1000000000"], "x 1000000000 steps"),
    (["plot", "fit.nc", "--out", "f.png", "--dpi", "1000000"], "--dpi 1e+06 needs about"),
    # a misspelt option is named, with the closest one (argparse reported '--speed' as missing)
    (["simulate", "--sped", "1"], "unrecognized option --sped (did you mean --speed?)"),
    # no scipy message: which target, why, and what is reachable
    (["target", "--e-n", "0.5", "--speed", "1e-8"], "target 1: e_n = 0.5 cannot be reached at v_n = 1e-08 m/s"),
]


#: of END_TO_END, run through the console script in a process of its own (what only the process
#: shows: the exit status and the stderr of the entry point's own handling): an argparse error, a
#: refused value, a failure deep in the work's set-up (scipy's root finding)
SUBPROCESS = {"simulate --sped 1", "simulate --speed 1e-300", "target --e-n 0.5 --speed 1e-8"}


@pytest.mark.parametrize("argv,words", END_TO_END, ids=[" ".join(a) for a, _ in END_TO_END])
def test_end_to_end_case_in_process(argv, words, workspace, capsys):
    """Each end-to-end case through ``main``: status 2, one line on stderr naming it, nothing written."""
    before = _snapshot(workspace)
    assert main(argv) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err.count("\n") == 1 and err.startswith("microimpact: error: ") and words in err, err
    assert _snapshot(workspace) == before


@pytest.mark.parametrize("argv,words", [c for c in END_TO_END if " ".join(c[0]) in SUBPROCESS],
                         ids=sorted(SUBPROCESS, key=[" ".join(a) for a, _ in END_TO_END].index))
def test_entry_point(argv, words, workspace):
    before = _snapshot(workspace)
    exe = shutil.which("microimpact")
    cmd = [exe, *argv] if exe else [sys.executable, "-m", "microimpact", *argv]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert r.returncode == 2, r.stderr
    assert r.stdout == ""
    assert r.stderr.count("\n") == 1 and r.stderr.startswith("microimpact: error: ") and words in r.stderr, r.stderr
    assert _snapshot(workspace) == before


_FIT_WITH_POSTERIOR = ["fit", "data.csv", "--out", "f.nc", "--posterior", "p.nc"]
INTERRUPTED = [
    pytest.param(_FIT_WITH_POSTERIOR, 1.5, id="fit-1.5s"),
    pytest.param(_FIT_WITH_POSTERIOR, 4.0, id="fit-4.0s"),
    # the latest moment, inside the posterior's sampling, waits 7 s: -m extended
    pytest.param(_FIT_WITH_POSTERIOR, 7.0, id="fit-7.0s", marks=pytest.mark.extended),
    pytest.param(["flags", "data.csv", "--fit", "fit.nc", "--out", "x.csv", "--nc", "x.nc"], 1.5, id="flags-1.5s"),
    pytest.param(["sweep", "--case", "2.3", "--out", "s.nc"], 1.5, id="sweep-1.5s"),
]


@pytest.mark.parametrize("argv,after", INTERRUPTED)
def test_ctrl_c_ends_in_one_line_with_status_130_and_writes_nothing(argv, after, workspace):
    """Ctrl-C (SIGINT to the process group, as a terminal sends it) at several moments of
    ``fit --posterior`` (reading, fitting, sampling), of ``flags`` and of ``sweep``: exit 130 within
    seconds, one line, no traceback (emcee once printed the likelihood's traceback: 87 lines), no
    file written."""
    import signal
    import time

    before = _snapshot(workspace)
    exe = shutil.which("microimpact")
    cmd = [exe] if exe else [sys.executable, "-m", "microimpact"]
    proc = subprocess.Popen([*cmd, *argv], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    time.sleep(after)
    if proc.poll() is not None:
        pytest.skip(f"{argv[0]} ended within {after} s, before the signal")
    sent = time.monotonic()
    os.killpg(proc.pid, signal.SIGINT)
    out, err = proc.communicate(timeout=60)
    assert time.monotonic() - sent < 10
    if proc.returncode in (0, -signal.SIGINT) and _snapshot(workspace) != before and "wrote" in out + err:
        # it had finished and written its outputs; the signal came during the interpreter's exit
        pytest.skip(f"{argv[0]} finished before the signal took effect")
    assert proc.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    last = err.strip().splitlines()[-1]
    after_snapshot = _snapshot(workspace)
    if last.startswith("microimpact: interrupted after writing "):
        # the signal came while the outputs were moved into place (held until all were): every
        # output named, each complete, no temporary file (CI 2026-11-27: x.csv and .x.nc.*.tmp)
        named = last.removeprefix("microimpact: interrupted after writing ").split(" (complete")[0].split(", ")
        assert sorted(set(after_snapshot) - set(before)) == sorted(named), err
        assert {k: v for k, v in after_snapshot.items() if k in before} == before
        return
    assert last.startswith("microimpact: interrupted; nothing was written"), err
    assert after_snapshot == before


def test_a_warning_is_one_line_naming_the_input_not_the_installation(tmp_path):
    """The console script prints a warning as ``microimpact: warning: ...`` on one line (Python's
    form was two lines naming cli.py and a source line of the installation). A measured e_n of
    1.006 with a stated uncertainty of 0.01 is kept as measured, with that warning."""
    csv = tmp_path / "impacts.csv"
    csv.write_text("id,material_pair,radius [um],speed [m/s],incidence_angle [deg],e_n [1],e_n_uncertainty [1]\n"
                   "a,ammonium_fluorescein_on_silicon,1.29,1.0,0,0.80,0.01\n"
                   "b,ammonium_fluorescein_on_silicon,1.29,2.0,0,1.006,0.01\n"
                   "c,ammonium_fluorescein_on_silicon,1.29,4.0,0,0.70,0.01\n")
    exe = shutil.which("microimpact")
    cmd = [exe] if exe else [sys.executable, "-m", "microimpact"]
    r = subprocess.run([*cmd, "fit", str(csv), "--out", str(tmp_path / "fit.nc"), "--no-confidence-intervals"],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    warned = [line for line in r.stderr.splitlines() if "warning:" in line.lower()]
    assert warned == ["microimpact: warning: impacts.csv: 1 measurement(s) outside the physical range by no more "
                      "than 4 stated standard uncertainties, kept as measured (e_n [1]: rows 2)"], r.stderr
    assert ".py:" not in r.stderr and "ImpactDataWarning" not in r.stderr, r.stderr
