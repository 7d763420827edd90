"""The numeric-option walk (issue 55, item 7): every numeric option of every command, given a
value that is no number (NaN, an infinity, ``1_0``, blanks, an empty string, hexadecimal, an
overflowing exponent), is refused before any work: exit 2, one line naming the option, no
traceback, nothing written. Negative, zero and huge values of the contact options either give a
result or are refused the same way (``lammps export``: the cheapest command that builds a contact
and writes a file); ``--work-of-adhesion 1e300`` ended in an OverflowError traceback and
``--time-budget 5e-324`` left its timer firing after the command (_runtime/timeout.py)."""

import argparse

import pytest

import microimpact.solvers.reference as reference
from microimpact import cli
from microimpact._commands import simulate as command
from microimpact._commands.contacts import contact_from_args
from microimpact.cli import main

#: the parsers of numeric options (cli.py); an option with another type is not numeric
NUMERIC = {"_finite_float", "_positive_float", "_non_negative_float", "_positive_int", "_seed", "_rtol",
           "_relative_uncertainty", "_target_points", "_verify_points", "_steps", "_incidence",
           "_angle_uncertainty", "<lambda>"}
NOT_NUMBERS = ["nan", "inf", "-inf", "1_0", " 2", "", "0x10", "1e999", "2,"]
PARSER = cli.build_parser()  # built once: the walk makes over a thousand calls


def _numeric_options():
    """(command words, option string, nargs) of every numeric option of the command line."""
    found = []

    def walk(parser, words):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    walk(sub, [*words, name])
            elif action.option_strings and getattr(action.type, "__name__", None) in NUMERIC:
                found.append((tuple(words), action.option_strings[-1], action.nargs))

    walk(cli.build_parser(), [])
    return found


OPTIONS = _numeric_options()


def test_the_walk_sees_the_numeric_options():
    # a walk over nothing asserts nothing: the parsers of the commands have this many numeric options
    assert len(OPTIONS) > 100
    assert {w[0] for w, _, _ in OPTIONS} >= {"simulate", "sweep", "fit", "flags", "target", "design", "plot", "lammps"}


@pytest.mark.parametrize("words, option, nargs", OPTIONS, ids=[" ".join([*w, o]) for w, o, _ in OPTIONS])
def test_a_value_that_is_no_number_is_one_line_naming_the_option(words, option, nargs, tmp_path, monkeypatch,
                                                                 capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(cli, "build_parser", lambda: PARSER)
    for value in NOT_NUMBERS:
        values = [value] * (nargs if isinstance(nargs, int) else 1)
        assert main([*words, f"{option}", *values]) == 2, (option, value)
        captured = capsys.readouterr()
        err = captured.err.strip().splitlines()
        assert len(err) == 1 and option in err[0] and "Traceback" not in captured.err, (option, value, err)
        assert captured.out == ""
    # the = form too (argparse reads "--x=-inf" on another path)
    assert main([*words, f"{option}=-inf", *["-inf"] * ((nargs if isinstance(nargs, int) else 1) - 1)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and option in err[0], (option, err)
    assert list(tmp_path.iterdir()) == []


CONTACT = [o for w, o, _ in OPTIONS if w == ("lammps", "export")]


@pytest.mark.parametrize("option", CONTACT)
def test_negative_zero_and_huge_contact_values_give_a_result_or_one_line(option, tmp_path, monkeypatch, capsys):
    # --work-of-adhesion 1e300 ended in an OverflowError traceback (Eq. 7 squares it)
    monkeypatch.setattr(cli, "build_parser", lambda: PARSER)
    for value in ["-1", "0", "1e300", "-1e300", "5e-324"]:
        out = tmp_path / "c.lmp"
        status = main(["lammps", "export", option, value, "--out", str(out)])
        captured = capsys.readouterr()
        assert "Traceback" not in captured.err, (option, value, captured.err)
        assert status in (0, 2, 3), (option, value, status, captured.err)  # 3: --time-budget ran out
        if status != 0:
            err = captured.err.strip().splitlines()
            assert len(err) == 1 and err[0].startswith("microimpact: error:"), (option, value, err)
            assert not out.exists(), (option, value)
        out.unlink(missing_ok=True)


def test_an_impossibly_long_reference_run_is_refused_before_the_work(monkeypatch, capsys):
    # simulate --method reference at zeta_H 1e6 ran for hours without a word
    def never(*args, **kwargs):
        raise AssertionError("the reference run started")

    monkeypatch.setattr(command, "simulate_impact", never)
    assert main(["simulate", "--speed", "2", "--method", "reference", "--zeta-hertz", "1e6"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--method reference" in err[0] and "--method engine" in err[0], err


@pytest.mark.parametrize("zeta", ["1e3", "3e3"])  # overdamped (C1 = 6.9, 20.8), a second or two each
def test_the_reference_work_estimate_follows_the_solver(zeta, monkeypatch):
    # the estimate against the evaluations solve_ivp reports for the same impact
    counted = []
    solve = reference.solve_ivp

    def counting(*args, **kwargs):
        sol = solve(*args, **kwargs)
        counted.append(sol.nfev)
        return sol

    monkeypatch.setattr(reference, "solve_ivp", counting)
    contact = contact_from_args(PARSER.parse_args(["simulate", "--speed", "2", "--zeta-hertz", zeta]))
    command.simulate_impact(contact, 2.0, 0.0, method="reference")
    # within a factor 2: an estimate for a bound (refused above ~1e7, where a factor 2 is minutes)
    assert 0.5 < command.reference_evaluations(contact, 2.0) / sum(counted) < 2.0, sum(counted)
