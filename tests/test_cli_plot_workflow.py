"""``microimpact plot`` and ``microimpact workflow``: their refusals (exit status 2, the culprit named,
nothing written, inputs unchanged) and how ``workflow`` builds the Snakemake command.

The drawing of every kind of result file and real runs of the packaged workflow are in
tests/test_workflow.py (they need the files of a pipeline run).
"""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from microimpact import cli
from microimpact.cli import main


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture
def foreign_nc(tmp_path) -> Path:
    """A valid NetCDF file that no microimpact command wrote."""
    path = tmp_path / "foreign.nc"
    xr.Dataset({"temperature": ("time", np.arange(3.0))}).to_netcdf(path)
    return path


def test_plot_refuses_a_netcdf_it_does_not_know(foreign_nc, tmp_path, capsys):
    out = tmp_path / "fig.png"
    assert main(["plot", str(foreign_nc), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert str(foreign_nc) in err and "not a microimpact result file" in err, err
    assert not out.exists()


def test_plot_refuses_a_file_that_is_not_netcdf(tmp_path, capsys):
    csv = tmp_path / "impacts.csv"
    csv.write_text("a,b\n1,2\n")
    out = tmp_path / "fig.pdf"
    assert main(["plot", str(csv), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert str(csv) in err and "NetCDF" in err, err
    assert not out.exists()


@pytest.mark.parametrize("name", ["fig.jpg", "fig", "fig.nc"])
def test_plot_refuses_an_output_without_a_figure_suffix(foreign_nc, tmp_path, capsys, name):
    out = tmp_path / name
    assert main(["plot", str(foreign_nc), "--out", str(out)]) == 2
    assert "--out" in capsys.readouterr().err
    assert not out.exists()


def test_plot_never_overwrites_its_input(foreign_nc, capsys):
    before = _sha(foreign_nc)
    assert main(["plot", str(foreign_nc), "--out", str(foreign_nc)]) == 2
    assert "input" in capsys.readouterr().err
    assert _sha(foreign_nc) == before


def test_plot_names_a_missing_file(tmp_path, capsys):
    assert main(["plot", str(tmp_path / "absent.nc"), "--out", str(tmp_path / "f.png")]) == 2
    assert "absent.nc" in capsys.readouterr().err


def test_workflow_passes_unknown_options_to_snakemake_in_order(tmp_path):
    args, rest = cli.build_parser().parse_known_args(
        ["workflow", "-n", "--config", "data=x.csv", "rtol=1.0e-9", "--directory", str(tmp_path), "results/kharaz.nc"])
    args.snakemake_args = rest
    command = cli._snakemake_command(args)
    assert command[:3] == [sys.executable, "-m", "snakemake"]
    assert command[command.index("--directory") + 1] == str(tmp_path)
    snakefile = Path(command[command.index("--snakefile") + 1])
    assert snakefile.name == "Snakefile" and (snakefile.parent / "workflow" / "config" / "config.yaml").is_file()
    assert command[-7:] == ["--cores", "all", "-n", "--config", "data=x.csv", "rtol=1.0e-9", "results/kharaz.nc"]


def test_workflow_config_paths_are_the_users_relative_to_where_they_typed_them(tmp_path, monkeypatch):
    """``--config data=impacts.csv`` names the file where the user is, not in the run directory
    Snakemake changes into (issue 28); a path that does not exist here is left for the config check."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "impacts.csv").write_text("x\n")
    args, rest = cli.build_parser().parse_known_args(
        ["workflow", "--directory", "run", "--config", "data=impacts.csv", "rtol=1e-9", "materials=nowhere.yaml",
         "--config=kharaz_data=impacts.csv"])
    args.snakemake_args = rest
    command = cli._snakemake_command(args)
    assert f"data={tmp_path / 'impacts.csv'}" in command
    assert "rtol=1e-9" in command and "materials=nowhere.yaml" in command
    assert f"--config=kharaz_data={tmp_path / 'impacts.csv'}" in command


@pytest.mark.slow  # 20 s or more: `pytest -m slow` (README, Tests), not the default run
def test_a_workflow_refused_at_start_leaves_no_run_directory_behind(tmp_path, capsys):
    """A bad config value stops Snakemake before any job; the run directory the command made for
    it is removed again (issue 28: an empty directory was left)."""
    run = tmp_path / "new_run"
    status = main(["workflow", "--directory", str(run), "-n", "--config", "rtol=2"])
    assert status != 0
    assert not run.exists()
    existing = tmp_path / "old_run"
    existing.mkdir()
    assert main(["workflow", "--directory", str(existing), "-n", "--config", "rtol=2"]) != 0
    assert existing.is_dir()  # not ours to remove
    dry = tmp_path / "dry_run"
    assert main(["workflow", "--directory", str(dry), "-n"]) == 0
    assert dry.is_dir()  # a run that worked keeps its directory (a dry run makes only .snakemake/)


@pytest.mark.parametrize("cores", [["--cores", "1"], ["-c2"], ["--jobs=4"], ["--profile", "workflow/profiles/slurm"]])
def test_workflow_keeps_the_cores_the_user_gives(cores):
    args = cli.build_parser().parse_args(["workflow"])
    args.snakemake_args = cores
    command = cli._snakemake_command(args)
    assert "all" not in command and command[-len(cores):] == cores


@pytest.mark.parametrize("option", [["-s", "Snakefile"], ["--snakefile=x"], ["-d", "elsewhere"], ["--directory=x"]])
def test_workflow_refuses_the_options_it_sets_itself(tmp_path, capsys, option):
    work = tmp_path / "w"
    assert main(["workflow", "--directory", str(work), "--", *option]) == 2
    assert "sets the Snakefile and the directory itself" in capsys.readouterr().err
    assert not work.exists()


def test_workflow_refuses_a_file_as_directory(tmp_path, capsys):
    file = tmp_path / "a_file"
    file.write_text("x")
    assert main(["workflow", "--directory", str(file), "-n"]) == 2
    assert "a_file" in capsys.readouterr().err and file.read_text() == "x"


def test_workflow_without_snakemake_asks_for_the_extra(tmp_path, capsys, monkeypatch):
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "snakemake" else real(name, *a))
    work = tmp_path / "w"
    assert main(["workflow", "--directory", str(work), "-n"]) == 2
    assert "pip install 'microimpact[workflow]'" in capsys.readouterr().err
    assert not work.exists()


def test_other_commands_still_refuse_unknown_arguments(capsys):
    assert main(["simulate", "--speed", "2", "--no-such-option"]) == 2
    assert "unrecognized option --no-such-option" in capsys.readouterr().err


def _workflow_running(tmp_path, **popen):
    """``microimpact workflow`` started in its own process group on a copy of data/, returned once
    its first result file exists: (command, run directory, environment, process)."""
    import os
    import shutil
    import subprocess
    import time

    exe = shutil.which("microimpact")
    cmd = [exe] if exe else [sys.executable, "-m", "microimpact"]
    run = tmp_path / "run"
    shutil.copytree(Path(__file__).resolve().parents[1] / "data", run / "data")
    env = dict(os.environ, PYTHONWARNINGS="ignore", MPLBACKEND="Agg")
    proc = subprocess.Popen([*cmd, "workflow", "--directory", str(run), "--cores", "2"], start_new_session=True,
                            env=env, **popen)
    deadline = time.monotonic() + 120
    while not list(run.glob("results/**/*.nc")) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert proc.poll() is None, "the run ended before it could be stopped"
    return cmd, run, env, proc


@pytest.mark.slow
def test_ctrl_c_of_the_workflow_ends_in_one_line_and_a_plain_rerun_resumes(tmp_path):
    """Ctrl-C of ``microimpact workflow`` (SIGINT to the process group): status 130, the wrapper's
    one line and no traceback; Snakemake stops its jobs and releases its lock (the wrapper used to
    kill it, leaving 'Directory cannot be locked'), and the same command again goes on without
    --unlock or --rerun-incomplete (shown by its dry run)."""
    import os
    import signal
    import subprocess

    cmd, run, env, proc = _workflow_running(tmp_path, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    os.killpg(proc.pid, signal.SIGINT)
    out, _ = proc.communicate(timeout=120)
    assert proc.returncode == 130, out[-3000:]
    assert out.strip().splitlines()[-1].startswith("microimpact: workflow interrupted"), out[-3000:]
    assert "Traceback" not in out.split("Error in rule")[0], out[-3000:]  # job tracebacks stay in the logs
    again = subprocess.run([*cmd, "workflow", "--directory", str(run), "--cores", "2", "-n"], capture_output=True,
                           text=True, env=env, timeout=300)
    assert again.returncode == 0, (again.stdout + again.stderr)[-3000:]
    assert "Job stats" in again.stdout, again.stdout[-3000:]  # jobs left to do, and nothing in the way


@pytest.mark.slow
@pytest.mark.skipif(not Path("/proc/self/cwd").exists(), reason="needs /proc to see other processes")
def test_a_killed_workflow_is_unlocked_by_the_rerun_only_when_nothing_holds_the_lock(tmp_path):
    """SIGKILL of ``microimpact workflow`` and its Snakemake leaves Snakemake's lock behind (a plain
    snakemake then stops with 'Directory cannot be locked'). The same command again removes it and
    says so, but not while a Snakemake process works in the directory: then it refuses with status
    2, naming the process, and the lock stays."""
    import os
    import signal
    import subprocess

    cmd, run, env, proc = _workflow_running(tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    locks = run / ".snakemake" / "locks"
    assert list(locks.glob("*.lock")), "the run ended before it could be killed"
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)
    assert list(locks.glob("*.lock"))  # the kill left the lock

    dry = [*cmd, "workflow", "--directory", str(run), "--cores", "2", "-n"]
    holder = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(120)", "snakemake"], cwd=run)
    try:
        refused = subprocess.run(dry, capture_output=True, text=True, env=env, timeout=120)
    finally:
        holder.kill()
        holder.wait()
    assert refused.returncode == 2, refused.stderr[-2000:]
    assert f"process {holder.pid}" in refused.stderr and "Traceback" not in refused.stderr, refused.stderr
    assert list(locks.glob("*.lock"))

    again = subprocess.run(dry, capture_output=True, text=True, env=env, timeout=300)
    assert again.returncode == 0, (again.stdout + again.stderr)[-3000:]
    assert "removed the lock that a stopped run left" in again.stderr, again.stderr[-2000:]
    assert "Job stats" in again.stdout and "cannot be locked" not in again.stdout + again.stderr
    assert not list(locks.glob("*.lock"))
