"""The hostile suite's matrices (issue 27, part 7): every pair of file options of a command made to
collide, every file option given a file of each wrong kind, every count option given huge values.

Rows are generated from the tables below, so a new option needs one line here. Each case asserts
exit status 2, one ``microimpact: error:`` line naming the option (and, for a wrong file, what the
file is), and that the work directory is byte-identical afterwards (nothing written, no input
touched). The work directory is tests/test_hostile_cli.py's, with a sweep file, a flags file and a
PDF added as further kinds of file.
"""

from __future__ import annotations

import itertools

import pytest

from microimpact.cli import main
from test_hostile_cli import _snapshot, fitted, workspace  # noqa: F401  (fixtures)

# every option against every other and every kind of file, hundreds of CLI runs: with the extended tests
pytestmark = pytest.mark.extended

#: command -> (argv with one placeholder per file option, {option: (placeholder, valid value, "in"/"out")})
COMMANDS = {
    "fit": (["fit", "{DATA}", "--config", "{--config}", "--out", "{--out}", "--posterior", "{--posterior}",
             "--oblique-out", "{--oblique-out}"],
            {"DATA": ("data.csv", "in"), "--config": ("m.yaml", "in"), "--out": ("f.nc", "out"),
             "--posterior": ("p.nc", "out"), "--oblique-out": ("b.nc", "out")}),
    "compare": (["compare", "{DATA}", "--config", "{--config}", "--out", "{--out}"],
                {"DATA": ("data.csv", "in"), "--config": ("m.yaml", "in"), "--out": ("c.nc", "out")}),
    "flags": (["flags", "{DATA}", "--fit", "{--fit}", "--config", "{--config}", "--out", "{--out}", "--nc", "{--nc}"],
              {"DATA": ("data.csv", "in"), "--fit": ("fit.nc", "in"), "--config": ("m.yaml", "in"),
               "--out": ("o.csv", "out"), "--nc": ("o.nc", "out")}),
    "sweep": (["sweep", "--case", "2.2", "--fit", "{--fit}", "--radius", "2e-6", "--out", "{--out}"],
              {"--fit": ("fit.nc", "in"), "--out": ("s_out.nc", "out")}),
    "target": (["target", "--e-n", "0.5", "--speed", "2", "--fit", "{--fit}", "--radius", "2e-6", "--out", "{--out}"],
               {"--fit": ("fit.nc", "in"), "--out": ("t.csv", "out")}),
    "plot": (["plot", "{RESULT}", "--out", "{--out}"], {"RESULT": ("fit.nc", "in"), "--out": ("p.png", "out")}),
    "lammps-export": (["lammps", "export", "--fit", "{--fit}", "--radius", "2e-6", "--out", "{--out}"],
                      {"--fit": ("fit.nc", "in"), "--out": ("c.lmp", "out")}),
    "lammps-verify": (["lammps", "verify", "{INPUT}", "--out", "{--out}"],
                      {"INPUT": ("contact.lmp", "in"), "--out": ("v.csv", "out")}),
    "lammps-fit": (["lammps", "fit", "{DATA}", "--config", "{--config}", "--out", "{--out}"],
                   {"DATA": ("data.csv", "in"), "--config": ("m.yaml", "in"), "--out": ("c.lmp", "out")}),
    "design": (["design", "{FIT}", "--n", "2", "--n-speeds", "5", "--out", "{--out}"],
               {"FIT": ("fit.nc", "in"), "--out": ("d.csv", "out")}),
    # flags reading a posterior: for the wrong kinds only (a posterior's collisions: test_hostile_cli.py)
    "flags-posterior": (["flags", "data.csv", "--fit", "fit.nc", "--posterior", "{--posterior}", "--out", "o.csv"],
                        {"--posterior": ("notfit.nc", "in")}),
    "design-posterior": (["design", "fit.nc", "--posterior", "{--posterior}", "--n", "2", "--out", "d.csv"],
                         {"--posterior": ("notfit.nc", "in")}),
}

#: how the error names each option (the positional inputs have no option name)
NAMES = {"DATA": "data file", "RESULT": "RESULT", "INPUT": "input file", "FIT": "fit file"}


def _argv(command: str, values: dict) -> list[str]:
    template, options = COMMANDS[command]
    filled = {k: values.get(k, v[0]) for k, v in options.items()}
    return [filled[w[1:-1]] if w.startswith("{") else w for w in template]


def _collisions():
    for command, (_, options) in COMMANDS.items():
        for out, other in itertools.permutations(options, 2):
            if options[out][1] == "out":
                yield command, out, other


COLLISIONS = list(_collisions())


@pytest.mark.parametrize("command,out,other", COLLISIONS, ids=[f"{c}:{o}={a}" for c, o, a in COLLISIONS])
def test_every_output_colliding_with_every_other_file_option_is_refused(command, out, other, workspace, capsys):
    """Output ``out`` given the path of ``other`` (an input, or another output): refused before any
    work, naming the output, and nothing is written or changed."""
    options = COMMANDS[command][1]
    before = _snapshot(workspace)
    argv = _argv(command, {out: options[other][0]})
    assert main(argv) == 2, argv
    err = capsys.readouterr().err
    assert err.startswith("microimpact: error: ") and err.count("\n") == 1, err
    assert NAMES.get(out, out) in err, err
    assert _snapshot(workspace) == before


#: file kinds made in the work directory -> file name
KINDS = {"fit": "fit.nc", "sweep": "sweep.nc", "flags": "flags.nc", "csv": "data.csv", "yaml": "m.yaml",
         "pdf": "doc.pdf", "foreign_nc": "notfit.nc", "garbage_nc": "garbage.nc", "empty": "zero.nc"}

#: (command, input option, the kinds it accepts)
FILE_INPUTS = [("fit", "DATA", {"csv"}), ("flags", "DATA", {"csv"}), ("flags", "--fit", {"fit"}),
               ("sweep", "--fit", {"fit"}), ("target", "--fit", {"fit"}), ("fit", "--config", {"yaml"}),
               ("flags", "--config", {"yaml"}), ("plot", "RESULT", {"fit", "sweep", "flags"}),
               ("flags-posterior", "--posterior", set()), ("lammps-export", "--fit", {"fit"}),
               ("lammps-verify", "INPUT", set()), ("lammps-fit", "DATA", {"csv"}), ("lammps-fit", "--config", {"yaml"}),
               ("compare", "DATA", {"csv"}), ("compare", "--config", {"yaml"}),
               ("design", "FIT", {"fit"}), ("design-posterior", "--posterior", set())]
WRONG_KIND = [(c, o, kind) for c, o, ok in FILE_INPUTS for kind in KINDS if kind not in ok]


@pytest.fixture(scope="session")
def made(fitted, tmp_path_factory):  # noqa: F811
    """A sweep, a flags file and a PDF, made once with the CLI itself."""
    data, fit = fitted
    d = tmp_path_factory.mktemp("kinds")
    assert main(["sweep", "--case", "2.2", "--out", str(d / "sweep.nc")]) == 0
    assert main(["plot", str(d / "sweep.nc"), "--out", str(d / "doc.pdf")]) == 0
    assert main(["flags", str(data), "--fit", str(fit), "--out", str(d / "f.csv"), "--nc", str(d / "flags.nc")]) == 0
    return d


@pytest.fixture
def kinds(workspace, made):
    """The work directory with a sweep file, a flags file and a PDF besides its fit, CSV and YAML."""
    import shutil

    for name in ("sweep.nc", "flags.nc", "doc.pdf"):
        shutil.copy(made / name, workspace / name)
    return workspace


@pytest.mark.parametrize("command,option,kind", WRONG_KIND, ids=[f"{c}:{o}<-{k}" for c, o, k in WRONG_KIND])
def test_every_file_option_refuses_every_wrong_kind_of_file(command, option, kind, kinds, capsys):
    """A file of the wrong kind is refused naming the option (or the positional file) and the file,
    and, for a file that is not text, saying what it is; nothing is written."""
    before = _snapshot(kinds)
    argv = _argv(command, {option: KINDS[kind]})
    capsys.readouterr()
    assert main(argv) == 2, argv
    err = capsys.readouterr().err
    assert err.startswith("microimpact: error: "), err
    assert KINDS[kind] in err, err
    if kind in ("fit", "sweep", "flags", "pdf") and option != "--config":
        assert "it is a" in err or "the file is a" in err or "is a" in err, err
    assert _snapshot(kinds) == before


#: (argv, option): counts far beyond what any machine holds or any run needs
HUGE = [(["fit", "data.csv", "--out", "f.nc", "--posterior", "p.nc", "--walkers", n], "--walkers") for n in
        ("1000000000", "10" * 20)]
HUGE += [(["fit", "data.csv", "--out", "f.nc", "--posterior", "p.nc", option, n], option)
         for option in ("--steps", "--max-steps") for n in ("1000000000000", "9" * 30)]
HUGE += [(["fit", "data.csv", "--out", "f.nc", "--posterior", "p.nc", "--seed", n], "--seed")
         for n in ("2147483648", "9" * 40)]
HUGE += [(["target", "--e-n", "0.5", "--speed", "2", "--points", n, "--out", "t.csv"], "--points")
         for n in ("1000000000000", "9" * 30)]
HUGE += [(["design", "fit.nc", option, n, "--out", "d.csv"], option) for option in ("--n", "--n-speeds", "--n-friction")
         for n in ("1000000000000", "9" * 30)]
HUGE += [(["plot", "fit.nc", "--out", "p.png", "--dpi", n], "--dpi") for n in ("1e7", "1e300")]
HUGE += [(["fit", "data.csv", "--out", "f.nc", option, "5"], option)  # sampler counts without a sampler
         for option in ("--walkers", "--steps", "--max-steps", "--seed")]


@pytest.mark.parametrize("argv,option", HUGE, ids=[" ".join(a[-2:]) for a, _ in HUGE])
def test_every_count_option_refuses_huge_counts_before_any_work(argv, option, workspace, capsys):
    """Refused at once (the memory estimate, the int32 seed, a sampler option without --posterior),
    naming the option; nothing written."""
    before = _snapshot(workspace)
    assert main(argv) == 2, argv
    err = capsys.readouterr().err
    assert err.startswith("microimpact: error: ") and option in err and err.count("\n") == 1, err
    assert _snapshot(workspace) == before


def test_the_matrices_cover_every_file_and_count_option_of_the_cli():
    """A new file option (a path: an input or an output) or count option of a command must get rows
    here: the parser's options are compared with the tables."""
    import argparse

    from microimpact import cli

    parser = cli.build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    covered_files = {(c.split("-")[0], o) for c, (_, opts) in COMMANDS.items() for o in opts}
    covered_files |= {(c, o) for c, (_, opts) in COMMANDS.items() for o in opts}  # lammps-export: a command's command
    covered_counts = {o for _, o in HUGE} | {"--points", "--dpi"}
    # stdout-only commands, directories (test_hostile_cli.py) and options that take no file
    not_files = {("simulate", "--fit"), ("simulate", "--config"), ("sweep", "--config"), ("target", "--config"),
                 ("lammps-export", "--config"), ("reproduce", "--out"), ("benchmark", "--out"), ("benchmark", "--docs"), ("plot", "--curves"),
                 ("workflow", "--directory")}
    file_like = ("--out", "--nc", "--fit", "--config", "--posterior", "--oblique-out", "--curves", "--docs",
                 "--directory")
    missing = []
    parsers = dict(sub.choices)
    for name, p in sub.choices.items():  # commands with their own commands (lammps export | verify)
        for action in p._actions:
            if isinstance(action, argparse._SubParsersAction):
                parsers |= {f"{name}-{inner}": q for inner, q in action.choices.items()}
    for name, p in parsers.items():
        for action in p._actions:
            opt = action.option_strings[-1] if action.option_strings else None
            if opt in file_like and (name, opt) not in covered_files | not_files:
                missing.append((name, opt))
            if getattr(action.type, "__name__", "") in ("_positive_int", "_seed") and opt not in covered_counts:
                missing.append((name, opt))
    assert not missing, missing
