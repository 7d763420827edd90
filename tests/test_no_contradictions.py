"""No printed statement contradicts the numbers beside it (issue 51 item 5).

:func:`contradictions` reads a printed text (the CLI's ``fit`` report, the PDF's text by pdftotext)
and lists every statement that the numbers next to it contradict:

* "not computed" / "not requested" on the line of an interval, or "confidence intervals not ..."
  anywhere a 95 % interval is printed;
* a fit that "converged" or "succeeded" (without "but") where the verdict rejects the model or a
  parameter is not determined;
* "adequate" with p < 0.001 or "inadequate" with p >= 0.001, and a p that is not the chi-square's
  (scipy.stats.chi2.sf, to the printed precision; "p < 1e-300" only where it underflows);
* an interval that does not contain its value; a standard error that is not the interval's
  (width / 3.92, to the printed precision);
* two different intervals for one parameter (compared to the precision of the coarser print;
  the interval widened by the misfit and the refit without the outliers are labelled, and are
  compared with their own kind);
* a printed NaN ("+nan", "nan %", "= nan", "[nan"), a sentence cut off after "do not determine";
* a rejected model's intervals without "conditional", an adequate one's with "rejected model".

:func:`json_contradictions` does the same for ``fit --json``, and against the text beside it.
The checker is tested on planted contradictions (it can fail); the fits of a clean, a rejected
and an outlier data set (microimpact.analysis.dirty_data) and the PDFs are then checked.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import re

import pypdf
import pytest
from scipy import stats

from microimpact import cli
from microimpact.analysis.dirty_data import make_outlier_impacts, make_rebound_only_impacts, make_thornton_impacts
from microimpact.io import write_csv
from microimpact.report.pdf import build_report

NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
PARAM = r"(zeta_hertz|zeta_adhesion|work_of_adhesion|friction|zeta_H|zeta_A|w_A)"
ALIAS = {"zeta_H": "zeta_hertz", "zeta_A": "zeta_adhesion", "w_A": "work_of_adhesion"}
INTERVAL = rf"\[({NUM}), ({NUM})\]"
Z95 = 1.959963984540054


def _half_unit(text: str) -> float:
    """Half the unit of the last printed digit of a number as printed ('18.1' -> 0.05)."""
    mant, _, exp = text.lower().partition("e")
    decimals = len(mant.split(".")[1]) if "." in mant else 0
    return 0.5 * 10.0 ** ((int(exp) if exp else 0) - decimals)


def _same(a: str, b: str) -> bool:
    return abs(float(a) - float(b)) <= _half_unit(a) + _half_unit(b) + 1e-12 * abs(float(a))


def _intervals(text: str) -> list[tuple]:
    """(parameter, kind, value, stderr, lo, hi) of every interval printed with its value."""
    out = []
    # between the value and "95 % interval": anything but an interval ("[1]", a unit, may come first)
    for m in re.finditer(rf"{PARAM}\s*=\s*({NUM})(?: \+/- ({NUM}))?(?:[^\[\n]|\[[^\],\n]*\])*?95 % interval {INTERVAL}",
                         text):
        out.append((m[1], "fit", m[2], m[3], m[4], m[5]))
    for m in re.finditer(rf"{PARAM} = ({NUM}), 95 % {INTERVAL}", text):  # the plot's caption
        out.append((m[1], "fit", m[2], None, m[3], m[4]))
    for m in re.finditer(rf"^\s+{PARAM}\s+({NUM}) {INTERVAL}\s+({NUM}) {INTERVAL}", text, re.M):  # side by side
        out += [(m[1], "fit", m[2], None, m[3], m[4]), (m[1], "without outliers", m[5], None, m[6], m[7])]
    for m in re.finditer(rf"^{PARAM}\s+\S+\s+({NUM})\s+(?:({NUM})\s+)?{INTERVAL}", text, re.M):  # PDF tables
        out.append((m[1], "fit", m[2], m[3], m[4], m[5]))
    return [(ALIAS.get(p, p), *rest) for p, *rest in out]


def _verdict_statements(text: str) -> list[tuple]:
    """(verdict or '', chi-square, dof, '=' or '<', p) of every chi-square test printed."""
    pat = rf"(?:\b(adequate|inadequate)\b:? \(?)?chi-square ({NUM}) for ({NUM}) degrees of freedom,? \(?p (=|<) ({NUM})"
    return [m.groups() for m in re.finditer(pat, text)]


def contradictions(text: str) -> list[str]:
    found = []
    lines = text.splitlines()
    has_interval = bool(re.search(r"95 % (?:interval )?\[", text))
    for line in lines:
        if re.search(r"not (?:computed|requested)", line) and re.search(INTERVAL, line):
            found.append(f"'not computed' beside an interval: {line.strip()}")
        if re.search(r"do not determine\s*$", line):
            found.append(f"a cut-off sentence: {line.strip()}")
    if has_interval and re.search(r"confidence intervals? not (?:computed|requested)", text):
        found.append("'confidence intervals not computed/requested' beside a printed 95 % interval")
    verdicts = _verdict_statements(text)
    rejected = any(v == "inadequate" for v, *_ in verdicts)
    undetermined = "not determined" in text
    for line in lines:
        if (re.search(r"least squares converged|\bsucceeded\b", line) and not re.search(r"\bbut\b|not converged", line)
                and (rejected or undetermined)):
            found.append(f"success claimed beside a rejection or an undetermined parameter: {line.strip()}")
    for verdict, chi2, dof, rel, p in verdicts:
        true_p = float(stats.chi2.sf(float(chi2), float(dof)))
        if verdict == "adequate" and not (rel == "=" and float(p) >= 1e-3):
            found.append(f"'adequate' with p {rel} {p}")
        if verdict == "inadequate" and not float(p) < 1e-3:
            found.append(f"'inadequate' with p {rel} {p}")
        if rel == "<" and not true_p < float(p):
            found.append(f"p < {p} where chi-square {chi2} for {dof} gives {true_p:.3g}")
        if rel == "=" and not (math.isclose(true_p, float(p), rel_tol=0.06) if float(p) > 0 else true_p == 0):
            found.append(f"p = {p} where chi-square {chi2} for {dof} gives {true_p:.3g}")
    seen = {}
    for name, kind, value, se, lo, hi in _intervals(text):
        if not float(lo) - _half_unit(lo) <= float(value) <= float(hi) + _half_unit(hi):
            found.append(f"{name} = {value} outside its interval [{lo}, {hi}]")
        if se is not None:
            width = float(hi) - float(lo)
            tol = (_half_unit(lo) + _half_unit(hi)) / (2 * Z95) + _half_unit(se)
            if abs(float(se) - width / (2 * Z95)) > tol + 1e-3 * float(se):
                found.append(f"{name}: standard error {se} is not the interval's ({width / (2 * Z95):.4g})")
        for other in seen.setdefault((name, kind), []):
            if not (_same(lo, other[0]) and _same(hi, other[1])):
                found.append(f"two intervals for {name} ({kind}): [{lo}, {hi}] and [{other[0]}, {other[1]}]")
        seen[(name, kind)].append((lo, hi))
    for bad in ("+nan", "nan %", "= nan", "[nan"):
        if bad in text.lower():
            found.append(f"a printed NaN: {bad!r}")
    if rejected and seen and "conditional" not in text:
        found.append("a rejected model's intervals without 'conditional'")
    if verdicts and not rejected and "rejected model" in text:
        found.append("an adequate model's intervals called conditional on a rejected model")
    return found


def json_contradictions(summary: dict, text: str = "") -> list[str]:
    """The same rules for ``fit --json`` (and against the text report of the same fit)."""
    found = []
    d = summary["damping"]
    v = d["verdict"]
    if v["verdict"] in ("adequate", "inadequate"):
        p = v["p_value"]
        if (v["verdict"] == "adequate") != (p >= 1e-3):
            found.append(f"verdict {v['verdict']} with p = {p}")
        if not math.isclose(p, stats.chi2.sf(v["chi_square"], v["degrees_of_freedom"]), rel_tol=1e-9, abs_tol=1e-300):
            found.append("p_value is not the chi-square's")
    if v["rejected"] != (v["verdict"] == "inadequate"):
        found.append("'rejected' disagrees with the verdict")
    if not math.isclose(v["chi_square"], d["chisqr"], rel_tol=1e-12):
        found.append("two chi-squares")
    printed = {(n, k): (lo, hi) for n, k, _, _, lo, hi in _intervals(text)}
    for part, kind in ((d, "fit"), (d.get("without_outliers"), "without outliers")):
        for name, rec in (part or {}).get("parameters", {}).items():
            if rec["status"] != "determined":
                if "interval" in rec or "stderr" in rec:
                    found.append(f"{name}: not determined, with an interval or a standard error")
                continue
            lo, hi = rec["interval"]
            if not lo <= rec["value"] <= hi:
                found.append(f"{name} outside its interval")
            if "stderr" in rec and not math.isclose(rec["stderr"], (hi - lo) / (2 * Z95), rel_tol=1e-9):
                found.append(f"{name}: stderr {rec['stderr']} is not the interval's")
            if (name, kind) in printed:
                plo, phi = printed[(name, kind)]
                if not (abs(lo - float(plo)) <= _half_unit(plo) * 1.0001 and abs(hi - float(phi)) <= _half_unit(phi) * 1.0001):
                    found.append(f"{name} ({kind}): --json [{lo}, {hi}] but the text [{plo}, {phi}]")
    if text:
        m = re.search(r"outliers\s+: ([^(]+) \(", text)
        named = [i.strip() for i in m[1].split(",")] if m else []
        if named != list(v["outlier_ids"]):
            found.append(f"outliers: --json {v['outlier_ids']}, text {named}")
    return found


# ----------------------------------------------------------------------------- the checker can fail
GOOD = """  verdict     : inadequate: chi-square 866.6 for 38 degrees of freedom (p = 3.2e-157)
    zeta_hertz       = 1.11937 +/- 0.0912 (8.2 %) [1]; 95 % interval [0.94301, 1.3007] (profile likelihood), conditional on the rejected model; widened by the misfit (x4.78): [0.27718, 1.9853]
  evaluations : 1921 (12.72 s), least squares converged, but the model does not describe the data (see the verdict)
"""


@pytest.mark.parametrize("planted, what", [
    (GOOD.replace("(p = 3.2e-157)", "(p = 0.2)"), "'inadequate' with p"),
    (GOOD.replace("inadequate:", "adequate:"), "'adequate' with p"),
    (GOOD.replace("p = 3.2e-157", "p = 3.2e-150"), "where chi-square"),
    (GOOD.replace("+/- 0.0912", "+/- 0.0904"), "standard error 0.0904"),
    (GOOD.replace("= 1.11937", "= 1.41937"), "outside its interval"),
    (GOOD.replace(", but the model does not describe the data (see the verdict)", ""), "success claimed"),
    (GOOD + "  note        : confidence intervals not computed: lmfit could not estimate the covariance\n",
     "confidence intervals not"),
    (GOOD + "  zeta_hertz       1.1194 [0.95, 1.3007]            0.73829 [0.57185, 0.90939]\n", "two intervals"),
    (GOOD.replace("8.2 %", "nan %"), "printed NaN"),
    (GOOD.replace("conditional on the rejected model; ", ""), "without 'conditional'"),
    (GOOD + "  evaluations : 12, least squares converged, but the data do not determine \n", "cut-off"),
])
def test_the_checker_finds_each_planted_contradiction(planted, what):
    assert contradictions(GOOD) == []
    assert any(what in c for c in contradictions(planted)), contradictions(planted)


def test_the_json_checker_finds_planted_contradictions():
    rec = {"status": "determined", "value": 1.0, "interval": [0.8, 1.2], "stderr": 0.4 / (2 * Z95)}
    good = {"damping": {"chisqr": 50.0, "parameters": {"zeta_hertz": rec},
                        "verdict": {"verdict": "adequate", "p_value": float(stats.chi2.sf(50.0, 38)),
                                    "chi_square": 50.0, "degrees_of_freedom": 38.0, "rejected": False,
                                    "outlier_ids": []}}}
    assert json_contradictions(good) == []
    bad = json.loads(json.dumps(good))
    bad["damping"]["parameters"]["zeta_hertz"]["stderr"] = 0.0904
    bad["damping"]["verdict"]["rejected"] = True
    found = json_contradictions(bad, "    zeta_hertz       = 1 +/- 0.102 [1]; 95 % interval [0.81, 1.2]\n")
    assert any("stderr 0.0904" in c for c in found) and any("'rejected'" in c for c in found)
    assert any("but the text [0.81, 1.2]" in c for c in found)


# ----------------------------------------------------------------------------- the PDF of the report fixture
def _pdf_text(path) -> str:
    # pypdf (a test dependency) rather than poppler's pdftotext, which a fresh machine may lack; its
    # layout mode keeps each printed line on a line of its own, as the report draws it
    return "\n".join(page.extract_text(extraction_mode="layout") for page in pypdf.PdfReader(path).pages)


def test_the_report_fixture_pdf_says_nothing_its_numbers_contradict(tmp_path):
    """The hand-built rejected fit of tests/test_report_verdict.py (a report of five sections, about
    7 s here: under the 10 s of a fast test)."""
    from test_report_verdict import VERDICT_ATTRS, _comparison, _dynamics, _fit, _flags
    _fit(VERDICT_ATTRS).to_netcdf(tmp_path / "fit.nc")
    _flags().to_csv(tmp_path / "flags.csv", index=False)
    path = build_report(tmp_path / "report.pdf", {"fit": tmp_path / "fit.nc", "flags": tmp_path / "flags.csv",
                                                 "model_comparison": _comparison([1310.0, 1500.0, 1420.0]),
                                                 "analyst_dynamics": _dynamics()})
    text = _pdf_text(path)
    assert _intervals(text) and _verdict_statements(text)  # else nothing was checked
    assert contradictions(text) == []


# ----------------------------------------------------------------------------- real fits (slow)
DATA = {"clean": make_rebound_only_impacts, "rejected": make_thornton_impacts, "outliers": lambda: make_outlier_impacts(2)}


@pytest.fixture(scope="module")
def printed(tmp_path_factory):
    """``microimpact fit`` (text, and --json) of each data set, in process: {kind: (text, summary, fit.nc)}."""
    out = {}
    for kind, make in DATA.items():
        tmp = tmp_path_factory.mktemp(kind)
        csv = write_csv(make(), tmp / f"{kind}.csv", float_format="%.6g")
        runs = []
        for extra in ([], ["--json"]):
            buf = io.StringIO()
            with contextlib.redirect_stdout(buf):
                assert cli.main(["fit", str(csv), "--out", str(tmp / f"fit{len(extra)}.nc"), *extra]) == 0
            runs.append(buf.getvalue())
        out[kind] = (runs[0], json.loads(runs[1]), tmp / "fit0.nc")
    return out


@pytest.mark.slow
@pytest.mark.parametrize("kind", list(DATA))
def test_fit_text_and_json_say_nothing_their_numbers_contradict(printed, kind):
    text, summary, _ = printed[kind]
    assert _intervals(text) and _verdict_statements(text)  # else nothing was checked
    assert contradictions(text) == []
    assert json_contradictions(summary, text) == []
    expected = {"clean": "adequate", "rejected": "inadequate", "outliers": "inadequate"}[kind]
    assert summary["damping"]["verdict"]["verdict"] == expected


@pytest.mark.slow
def test_the_pdf_of_a_real_rejected_fit_says_nothing_its_numbers_contradict(printed, tmp_path):
    for kind in ("outliers", "rejected"):
        path = build_report(tmp_path / f"{kind}.pdf", {"fit": printed[kind][2]})
        text = _pdf_text(path)
        assert _intervals(text) and _verdict_statements(text)
        assert contradictions(text) == [], kind
