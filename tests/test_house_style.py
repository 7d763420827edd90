"""House style of the README and the docstrings (issue 50): the README is a short entry, and
neither it nor any docstring of the package carries measurements, dates or history.

Measurements (timings, speed-ups, load averages, the machine they were taken on) live in the
outputs of the studies (docs/studies.md, docs/*.json) and history lives in git: prose that quotes
them goes stale with the next change or the next machine. What is caught:

- a date: ISO (``2026-11-29``) or a month with its year (``November 2026``, ``Nov 29, 2026``);
  a year in a citation (``Cheng et al. (2002)``) and the date that names a cited software version
  (``version 22 Jul 2025``, LAMMPS's way) are not dates of this project;
- a timing: a plain number, or range of numbers, followed by a unit of time (``1.6-1.9 s``,
  ``0.6 ms per call``, ``17 minutes``); a number in scientific notation (``T = 2.3e-8 s``, a time
  scale of the physics) and a unit in brackets (``[s]``) or in words without a number (``seconds``)
  are not;
- a speed-up: ``17,125x``, ``1.5x slower``, ``3 times faster``;
- the state of the machine: a ``load average`` with its number, ``on the 2-core machine``,
  ``on this machine``, ``idle machine``, ``loaded machine``;
- a ``Length:`` paragraph (a docstring says what and why, not how long its function is).

Doctest examples (``>>>`` lines and their output) and inline literals (````...````) are not prose:
the output of a formatting function may well read ``'500 ms'``.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PACKAGE = REPO / "toolkit" / "microimpact"
README_MAX_LINES = 150

_MONTHS = ("January|February|March|April|May|June|July|August|September|October|November|December"
           "|Jan|Feb|Mar|Apr|Jun|Jul|Aug|Sep|Sept|Oct|Nov|Dec")
#: a number not part of scientific notation, a word or a version (no letter, digit, '.', '-' or
#: '+' just before it; thousands separated by commas)
_NUMBER = r"(?<![\w.+\-^/])\d+(?:,\d{3})*(?:\.\d+)?"
#: no bare "h": in a solver's docstring "5 h" is five step sizes
_TIME_UNIT = r"(?:ms|us|µs|ns|s|sec|secs|seconds?|min|mins|minutes?|hours?)"

#: kind -> pattern of what the house style keeps out of the README and the docstrings
PATTERNS = {
    "date": re.compile(rf"\b(?:19|20)\d\d-[01]\d-[0-3]\d\b"
                       rf"|\b(?:{_MONTHS})\.?\s+(?:[0-3]?\d(?:st|nd|rd|th)?,?\s+)?(?:19|20)\d\d\b"
                       rf"|\b[0-3]?\d\s+(?:{_MONTHS})\.?\s+(?:19|20)\d\d\b"),
    "timing": re.compile(rf"{_NUMBER}(?:\s*(?:-|to|and)\s*\d+(?:,\d{{3}})*(?:\.\d+)?)?\s*{_TIME_UNIT}"
                         r"(?![\w/^(\-])"),
    "speed-up": re.compile(rf"{_NUMBER}\s*(?:x|times)\s+(?:faster|slower|quicker)\b"
                           r"|(?<![\w.])\d{1,3}(?:,\d{3})+(?:\.\d+)?x\b"),
    "machine": re.compile(r"\bload average[^.;\n]{0,30}?\d|\b\d+-core (?:test )?machine\b"
                          r"|\b(?:idle|loaded) machine\b|\bon (?:this|my|our) machine\b", re.I),
    "length paragraph": re.compile(r"^\s*Length:", re.M),
}

#: a date right after this names a software version (``version 22 Jul 2025``), not an event
_VERSION_BEFORE = re.compile(r"\bversion\s+(?:[0-3]?\d\s+)?$")

#: what the patterns must catch (the measurements the issue found), and what they must let through
MUST_CATCH = {
    "date": ["before 2026-11-29 the solver", "measured in November 2026", "on Nov 29, 2026 it"],
    "timing": ["took 1.6-1.9 s against", "0.6 ms per call on one thread", "up to 40 ms on two threads",
               "in 17 minutes", "about 2 s warm", "10-22 s per solver", "0.24 us per impact"],
    "speed-up": ["measured 1.5x slower", "17,125x DOP853", "3 times faster"],
    "machine": ["at a load average of 0.9", "on the 2-core machine", "on the loaded machine",
                "about 4x less on this machine"],
    "length paragraph": ["Does a thing.\n\n    Length: 40 lines, because ..."],
}
MUST_PASS = [
    "time_budget : float, seconds", "contact_time : float [s]", "speed [m/s] of the sphere",
    "Cheng, Brach & Dunn (2002)", "Johnson (1985), Sec. 7.2", "a time scale T = 2.3e-8 s",
    "C_H in s/m", "damping 0.003163 s/m", "rtol 1e-8", "version 0.1.0", "up to 100x the rolling spin",
    "omega_f in rad/s", "1/s", "Eq. (27)", "the budget in s",
    "x'' = -x^(3/2)", "C ~ v^(-1/5): 32 times the speed halves it", "a 2-D grid", "the 3-D model", "measured impacts", "one s-shaped curve",
    "LAMMPS documentation (version 22 Jul 2025)", "the grown step is 5 h",
    "the 1-minute load average (NaN where the OS has none)",
    ">>> format_duration(0.5)\n'500 ms'\n\nThe end.", "a bar ``37% 2.1 s, ~3.6 s left``",
]


def prose(text: str) -> str:
    """``text`` without its doctest examples (``>>>`` and ``...`` lines and the output after them,
    up to a blank line) and its inline literals (````...````)."""
    kept, in_example = [], False
    for line in text.splitlines():
        stripped = line.strip()
        if stripped.startswith((">>>", "... ")) or stripped == "...":
            in_example = True
        elif not stripped:
            in_example = False
        if not in_example:
            kept.append(line)
    return re.sub(r"``.*?``", "````", "\n".join(kept), flags=re.S)


def offences(text: str) -> list[tuple[str, str]]:
    """(kind, matched text) of every measurement, date or history the house style keeps out."""
    text = prose(text)
    return [(kind, m.group(0)) for kind, pattern in PATTERNS.items() for m in pattern.finditer(text)
            if not (kind == "date" and _VERSION_BEFORE.search(text, 0, m.start()))]


def docstrings(path: Path) -> list[tuple[str, str]]:
    """(where, docstring) of the module, its classes and functions (methods included)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    found = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            doc = ast.get_docstring(node, clean=False)
            if doc:
                name = "module" if isinstance(node, ast.Module) else f"{node.name} (line {node.lineno})"
                found.append((name, doc))
    return found


@pytest.mark.parametrize("kind", sorted(MUST_CATCH))
def test_the_patterns_catch_measurements(kind):
    for text in MUST_CATCH[kind]:
        assert any(k == kind for k, _ in offences(text)), f"{kind} not caught in {text!r}"


@pytest.mark.parametrize("text", MUST_PASS)
def test_the_patterns_let_units_and_citations_through(text):
    assert offences(text) == [], text


def test_the_readme_is_short():
    lines = (REPO / "README.md").read_text().splitlines()
    assert len(lines) <= README_MAX_LINES, f"README.md has {len(lines)} lines (at most {README_MAX_LINES}): " \
                                           "the manual belongs in docs/"


def test_the_readme_holds_no_measurements_dates_or_history():
    found = offences((REPO / "README.md").read_text())
    assert not found, f"README.md: {found} (measurements: docs/studies.md and the JSON files; history: git)"


def test_no_docstring_holds_measurements_dates_or_history():
    modules = sorted(PACKAGE.rglob("*.py"))
    assert len(modules) > 20
    found = [f"{path.relative_to(REPO)}: {where}: {kind} {text!r}"
             for path in modules for where, doc in docstrings(path) for kind, text in offences(doc)]
    assert not found, "measurements, dates or history in docstrings (say what and why; numbers belong " \
                      "in the studies' outputs, history in git):\n" + "\n".join(found)
