"""A LAMMPS file is data (issue 55, item 1): ``lammps verify`` reads only the lines ``lammps export``
writes and runs LAMMPS on the command it rebuilds, never the file's text; ``lammps export`` writes
no second command; LAMMPS's own errors are one line, exit 2; every lammps command has a budget.

The parsing tests run everywhere; those that run LAMMPS are skipped without it (as in test_lammps.py).
"""


import pytest

from microimpact import Contact
from microimpact.cli import main
from microimpact.io.lammps import LammpsExportError, lammps_input, read_lammps_export

# a JKR contact of Table 1 row 2's sphere (Cheng et al. 2002), undamped: LAMMPS can write it
JKR = Contact(radius=3.45e-6, density=1350.0, stiffness=1.776e9, adhesion_line_force=7.422, normal_model="jkr_force")


def _one_error_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("microimpact: error: ") and "Traceback" not in err, err
    return lines[0]


@pytest.fixture
def export(tmp_path):
    path = tmp_path / "contact.lmp"
    path.write_text(lammps_input(JKR, units="micro"))
    return path


def _hostile(text: str, witness: str) -> dict:
    lines = text.splitlines(keepends=True)
    fix = len(lines)  # 1-based line of the fix command, the last
    return {  # name: (text, the line number the refusal must name)
        "shell after": (text + f"shell touch {witness}\n", fix + 1),
        "shell before the fix": ("".join(lines[:-1]) + f"shell touch {witness}\n" + lines[-1], fix),
        "shell first": (f"shell touch {witness}\n" + text, 1),
        "run": (text + "run 2000000000\n", fix + 1),
        "include": (text + "include /etc/passwd\n", fix + 1),
        "python": (text + "python f source here \"import os\"\n", fix + 1),
        "unknown in the header": ("".join(lines[:2]) + "variable x equal 1\n" + "".join(lines[2:]), 3),
        "units real": ("units real\n" + text, 1),
        "blank line": ("".join(lines[:2]) + "\n" + "".join(lines[2:]), 3),
        "a second fix": (text + lines[-1], fix + 1),
        "a carriage return": (text.replace(" NULL\n", f" NULL\rshell touch {witness}\n"), fix),
        "a command among the comments": (
            text.replace("THIS_FILE\n", f"THIS_FILE\nshell touch {witness}\n"),
            next(i for i, line in enumerate(lines, 1) if line.startswith("# check with")) + 1),
        "garbled normal law": (text.replace("granular jkr ", "granular jkrx "), fix),
        "a changed modulus": (text.replace(lines[-1], lines[-1].replace(" jkr ", " jkr 1", 1)), fix),
        "a second command on the fix line": (text.replace(" NULL\n", " NULL shell touch X\n"), fix),
        "a semicolon-free extra word": (text.replace(" NULL\n", " NULL & \n"), fix),
    }


@pytest.mark.parametrize("case", list(_hostile(lammps_input(JKR, units="micro"), "W")))
def test_verify_refuses_every_line_the_export_does_not_write_naming_it(case, export, tmp_path, capsys):
    witness = tmp_path / "PWNED"
    text, line = _hostile(export.read_text(), str(witness))[case]
    with pytest.raises(ValueError, match=rf"^line {line}: "):
        read_lammps_export(text)
    hostile = tmp_path / "hostile.lmp"
    hostile.write_bytes(text.encode())
    # refused before LAMMPS is loaded: this part runs with or without LAMMPS
    assert main(["lammps", "verify", str(hostile), "--speeds", "1", "--incidence-deg", "0"]) == 2
    err = _one_error_line(capsys.readouterr().err)
    assert f"input file {hostile}: line {line}: " in err
    assert not witness.exists()


def test_the_export_reads_back_whole_and_verify_runs_the_rebuilt_command(needs_lammps, export, monkeypatch):
    from microimpact.studies import lammps_check

    parsed = read_lammps_export(export.read_text())
    assert parsed.contact == JKR and parsed.units == "micro" and parsed.fix_line_number == len(
        export.read_text().splitlines())
    assert parsed.script() == export.read_text().splitlines()[-1] + "\n"
    seen = []
    real = lammps_check.lammps_impact

    def recording(lammps, text, *args, **kwargs):
        seen.append(text)
        return real(lammps, text, *args, **kwargs)

    monkeypatch.setattr(lammps_check, "lammps_impact", recording)
    # a header comment that LAMMPS would skip but the file's text is not what is run
    text = export.read_text().replace("# sphere: ", "# sphere: (a comment LAMMPS would skip) ")
    table = lammps_check.verify_lammps(text, speeds=(1.0,), incidences=(0.0,))
    assert table.attrs["passed"]
    assert seen and set(seen) == {parsed.script()}  # only the rebuilt fix command, no comment, no header


@pytest.mark.parametrize("wall", ["zplane 0.0 NULL\nshell touch X", "zplane 0.0 NULL\rshell touch X",
                                  "zplane 0.0 NULL\x1b[2J", "zplane 0.0 NULL shell touch X", "region r1", ""])
def test_export_refuses_a_wall_that_is_not_a_wall(wall, tmp_path, capsys):
    out = tmp_path / "contact.lmp"
    assert main(["lammps", "export", "--zeta-hertz", "0", "--zeta-adhesion", "0", "--friction", "0",
                 "--normal-model", "jkr_force", "--wall", wall, "--out", str(out)]) == 2
    assert "--wall" in _one_error_line(capsys.readouterr().err)
    assert not out.exists()


@pytest.mark.parametrize("field", ["source", "fitted"])
def test_the_header_strings_hold_no_control_character(field):
    hostile = "fit.nc\nshell touch X"
    kwargs = {"source": hostile} if field == "source" else {"fitted": {"w_A": hostile}}
    with pytest.raises(LammpsExportError, match="U\\+000A"):
        lammps_input(JKR, **kwargs)


def test_every_lammps_command_takes_a_time_budget(needs_lammps, export, tmp_path, capsys):
    from microimpact.cli import build_parser

    for words in (["export", "--out", "x"], ["fit", "d.csv", "--out", "x"], ["verify", "f"]):
        assert build_parser().parse_args(["lammps", *words, "--time-budget", "2"]).time_budget == 2.0
    # a million steps per contact time runs for minutes; the budget stops it, exit 3, one line
    status = main(["lammps", "verify", str(export), "--speeds", "1", "--incidence-deg", "0", "--steps", "1000000",
                   "--time-budget", "0.5"])
    assert status == 3
    assert "lammps verify: time budget of 0.5 s exceeded" in _one_error_line(capsys.readouterr().err)


def test_a_lammps_error_is_one_line_naming_file_and_line_with_status_2(needs_lammps, export, capsys):
    # at 1e6 m/s the sphere passes through the wall within one step: LAMMPS stops with "Lost atoms"
    assert main(["lammps", "verify", str(export), "--speeds", "1e6", "--incidence-deg", "0"]) == 2
    err = _one_error_line(capsys.readouterr().err)
    fix = len(export.read_text().splitlines())
    assert f"input file {export}, line {fix} " in err and "ERROR: Lost atoms" in err
