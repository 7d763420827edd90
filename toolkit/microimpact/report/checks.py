"""Part C of the report: checks of the model and the numerics, and the configuration appendix.

Sections: the Kharaz et al. (2001) validation, the work-precision benchmark, the seeded stress
sweep of the engine and the configuration the report was made with.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping

import numpy as np
import pandas as pd
import xarray as xr
import yaml

from microimpact.report import figures
from microimpact.report.inputs import parameter_source
from microimpact.report.layout import Layout

__all__ = ["kharaz_section", "benchmark_section", "stress_section", "lammps_section", "config_section"]

#: units and distribution of each input of the stress sweep (microimpact.studies.stress.draw_cases)
STRESS_INPUTS = {
    "radius": ("r", "m", "log-uniform"),
    "speed": ("|v_i|", "m/s", "log-uniform"),
    "density": ("rho", "kg/m^3", "log-uniform"),
    "stiffness": ("K", "Pa", "log-uniform"),
    "work_of_adhesion": ("w_A", "J/m^2", "log-uniform, or exactly 0"),
    "zeta_hertz": ("zeta_H", "-", "log-uniform, or exactly 0"),
    "zeta_adhesion": ("zeta_A", "-", "log-uniform, or exactly 0"),
    "friction": ("f", "-", "uniform, or exactly 0"),
    "incidence_deg": ("alpha", "deg", "uniform, or exactly 0"),
    "azimuth_deg": ("theta", "deg", "uniform"),
    "spin_ratio": ("r omega_i / v", "-", "each component uniform in +/- max, or no spin"),
}

#: failed cases listed in the report (all of them are in results/stress_summary.json)
STRESS_MAX_LISTED = 30

_FAILED_COLUMNS = {"case": 6, "checks": 11, "radius": 8, "speed": 8, "incidence_deg": 6, "azimuth_deg": 6,
                   "density": 8, "stiffness": 8, "work_of_adhesion": 8, "zeta_hertz": 8, "zeta_adhesion": 8,
                   "friction": 6, "omega_n": 9, "omega_t": 9, "omega_tp": 9}
_FAILED_HEADERS = {"radius": "r [m]", "speed": "v [m/s]", "incidence_deg": "alpha", "azimuth_deg": "theta",
                   "density": "rho", "stiffness": "K [Pa]", "work_of_adhesion": "w_A", "zeta_hertz": "zeta_H",
                   "zeta_adhesion": "zeta_A", "friction": "f", "omega_n": "omega_n", "omega_t": "omega_t",
                   "omega_tp": "omega_t'"}


# =============================================================================== Kharaz et al. (2001)
def kharaz_section(lay: Layout, kh: xr.Dataset) -> None:
    """Model against the oblique impacts of Kharaz et al. (2001): figure, friction, RMS table.

    Examples
    --------
    The comparison without the friction fit and with model curves at two angles only (to keep the
    example short): one figure, and the RMS table, whose row of the tangential restitution below
    30 deg shows the hysteretic Mindlin-Deresiewicz law (last column) about half as far from the
    measurements as the rigid contact (first column):

    >>> from microimpact.analysis.kharaz import kharaz_comparison
    >>> from microimpact.report.layout import Layout
    >>> lay = Layout("Report")
    >>> kharaz_section(lay, kharaz_comparison(fit_friction=False, curve_incidence_deg=[10.0, 45.0]))
    >>> text = "\\n".join(t.get_text() for p in lay.pages for t in p.figure.texts)
    >>> lay.contents, sum(len(p.figure.axes) for p in lay.pages)
    ([('1. Validation: oblique impacts of Kharaz et al. (2001)', 0)], 1)
    >>> print(next(line for line in text.splitlines() if line.startswith("tangential_restitution") and "<=" in line))
    tangential_restitution  1        <= 30 deg   0.07541                     0.1303         0.03803
    """
    lay.section("Validation: oblique impacts of Kharaz et al. (2001)")
    lay.paragraph(
        "Real measurements (digitized): 5 mm alumina spheres on soda-lime glass at 3.9 m/s. They test the "
        "tangential/rotational part of the model in its non-adhesive limit; microsphere data with rotation "
        f"are not publicly available. {kh.attrs.get('conditions', '')}")
    lay.source(parameter_source(kh))
    lay.plot(figures.plot_kharaz(kh), max_height=3.2)
    if "friction" in kh and "fitted_friction" in kh:
        lay.paragraph(
            f"Friction: nominal {float(kh['friction']):.4g}; fitted to the tangential restitution above "
            f"{kh.attrs.get('sliding_threshold_deg', 30):g} deg: {float(kh['fitted_friction']):.4g} +/- "
            f"{float(kh.get('fitted_friction_stderr', np.nan)):.2g}. Model sliding/rolling transition at "
            f"{float(kh['transition_angle']):.3g} deg.")
    if "effective_shear_modulus" in kh:
        lay.paragraph(
            "Rigid vs compliant: the paper's contact is tangentially rigid. The compliant models add the "
            "Mindlin tangential stiffness 8 G* a with micro-slip and the same Coulomb limit: elastic "
            "(tangential_model = mindlin, no memory: micro-slip energy is given back on unloading) and "
            "hysteretic (tangential_model = mindlin_deresiewicz: Mindlin-Deresiewicz loading/unloading "
            "memory in Thornton's incremental form, energy lost to micro-slip at each reversal); "
            f"G* = {float(kh['effective_shear_modulus']) / 1e9:.4g} GPa comes from the shear "
            "moduli and Poisson ratios of the materials config and the friction is the nominal one: nothing is "
            "fitted. The table gives the RMS of each model per angle range; the figure shows where each departs "
            "from the measurements.")
    lay.heading("RMS model - measured")
    lay.table(_kharaz_rms(kh), {"quantity": 22, "units": 7, "regime": 10, "nominal": 12, "fitted": 12, "compliant": 13,
                                "hysteretic": 13},
              headers={"nominal": "rigid, nominal f", "fitted": "rigid, fitted f", "compliant": "elastic MS, nom. f",
                       "hysteretic": "hysteretic, nom. f"},
              size=7.2)
    readings = _kharaz_readings(kh)
    if len(readings):
        lay.heading("Hysteretic law: a turning point held by a falling load")
        lay.paragraph(
            "Right after a turning point the contact sticks everywhere; when the normal load then falls, "
            "the force there must follow some rule, and Thornton's (1991) law can be read in several ways. "
            "The solvers keep the force's ratio to the Coulomb limit (k = 1, 'limit'); the others keep a "
            "falling share of it, T ~ F_lim^k, as DEM codes do with their tangential history. k = 0 (the "
            "force kept) makes a shrinking stuck contact create energy (stored energy ~ a^(6k - 1)). The "
            "alternatives come from an independent scipy integration of the law, whose 'limit' reading "
            f"reproduces the compiled solver to {kh.attrs.get('hysteretic_reference_difference', math.nan):.1g} "
            "in the tangential restitution. RMS of the tangential restitution, nominal friction, nothing fitted:")
        lay.table(readings, {"reading": 22, "k": 6, "held force": 46, "sliding": 9, "below": 9, "all": 9},
                  size=7.2)


def _kharaz_readings(kh: xr.Dataset) -> pd.DataFrame:
    """RMS of the tangential restitution per reading of a held hysteretic turning point: the
    solvers' ("limit", ``_hysteretic``) and the ``_md_<reading>`` attributes; empty if absent."""
    text = kh.attrs.get("unloading_readings", "")
    rows = []
    for item in filter(None, (t.strip() for t in text.split(";"))):
        m = re.fullmatch(r"(\w+) \(k = ([\d.]+), (_\w+)\): the held force (.+)", item)
        if not m:
            continue
        name, k, suffix, what = m.groups()
        rows.append({"reading": name, "k": k, "held force": what,
                     **{regime: float(kh.attrs.get(f"rms_tangential_restitution_{regime}{suffix}", math.nan))
                        for regime in ("sliding", "below", "all")}})
    return pd.DataFrame(rows, columns=["reading", "k", "held force", "sliding", "below", "all"])


def _kharaz_rms(kh: xr.Dataset) -> pd.DataFrame:
    """The ``rms_<quantity>_<regime>[_fitted|_compliant|_hysteretic]`` attributes of the comparison file as a table."""
    threshold = float(kh.attrs.get("sliding_threshold_deg", 30.0))
    regimes = {"sliding": f"> {threshold:g} deg", "below": f"<= {threshold:g} deg", "all": "all"}
    rows = []
    for key, value in kh.attrs.items():
        m = re.fullmatch(r"rms_(.+)_(sliding|below|all)", key)
        if not m:
            continue
        q, regime = m.groups()
        units = kh[f"{q}_measured"].attrs.get("units", "") if f"{q}_measured" in kh else ""
        rows.append({"quantity": q, "units": units, "regime": regimes[regime], "nominal": float(value),
                     "fitted": float(kh.attrs.get(f"{key}_fitted", math.nan)),
                     "compliant": float(kh.attrs.get(f"{key}_compliant", math.nan)),
                     "hysteretic": float(kh.attrs.get(f"{key}_hysteretic", math.nan))})
    return pd.DataFrame(rows, columns=["quantity", "units", "regime", "nominal", "fitted", "compliant", "hysteretic"])


# =============================================================================== benchmark
def benchmark_section(lay: Layout, wp: xr.Dataset | None) -> None:
    """The work-precision diagram of the solvers and the most accurate setting of each.

    Examples
    --------
    Switched off in the configuration, the section says so and how to include it:

    >>> from microimpact.report.layout import Layout
    >>> lay = Layout("Report")
    >>> benchmark_section(lay, None)
    >>> lay.contents, "benchmark={enabled: true}" in lay.page.figure.texts[-1].get_text()
    ([('1. Work-precision benchmark', 0)], True)
    """
    lay.section("Work-precision benchmark", new_page=False, keep=3.0)
    if wp is None:
        lay.paragraph("The work-precision benchmark was switched off in the configuration (benchmark.enabled: "
                      "false); run with --config 'benchmark={enabled: true}' to include it.")
        return
    a = wp.attrs
    quick = str(a.get("quick", "")).lower() in ("1", "true")
    lay.paragraph(
        f"{str(a.get('title', 'Work-precision benchmark')).capitalize()} (microimpact.studies.benchmark"
        f"{', quick mode: small test set, few settings' if quick else ', full study'}): "
        f"{a.get('n_normal_speeds', '?')} normal impacts from just above the capture speed "
        f"({float(a.get('capture_speed', math.nan)):.4g} m/s) to 100 m/s and {a.get('n_oblique_cases', '?')} oblique "
        f"impacts. Reference: {a.get('reference', '?')}. Machine: {a.get('machine_processor', '?')}, "
        f"{a.get('machine_cpu_count', '?')} cores (1-min load average at start "
        f"{float(a.get('machine_load_average_1min_at_start', math.nan)):.2g}); "
        f"the benchmark took {float(a.get('total_seconds', math.nan)):.3g} s.")
    lay.source(parameter_source(wp))
    lay.plot(figures.plot_work_precision(wp), max_height=3.6)
    rows = _most_accurate(wp)
    if len(rows):
        lay.heading("Most accurate setting of each method")
        lay.table(rows, {"method": 13, "err": 12, "time": 14, "fast": 14, "timing": 60},
                  headers={"err": "max |e_n err|", "time": "time/impact [s]", "fast": "fastest [s]",
                           "timing": "how timed"}, size=7.0)
    ratio = a.get("ratio_dop853_to_engine_single")
    if ratio is not None:
        lay.paragraph(
            f"At the target error {float(a.get('target_error_e_n', math.nan)):.0e} in e_n: DOP853 / engine time ratio "
            f"{float(ratio):.3g} (single calls), {float(a.get('ratio_dop853_to_engine_batch', math.nan)):.3g} (batch); "
            f"targets {float(a.get('target_ratio', math.nan)):g} (the engine) and "
            f"{float(a.get('single_call_target_ratio', math.nan)):g} (one call). {a.get('target_ratio_note', '')}")


def _most_accurate(wp: xr.Dataset) -> pd.DataFrame:
    rows = []
    for i, m in enumerate(wp["method"].values):
        err = np.asarray(wp["max_error_e_n"].isel(method=i).values, float)
        t = np.asarray(wp["time_per_impact"].isel(method=i).values, float)
        ok = np.isfinite(err) & np.isfinite(t)
        if not ok.any():
            continue
        j = int(np.argmin(np.where(ok, err, np.inf)))
        rows.append({"method": str(m), "err": f"{err[j]:.3g}", "time": f"{t[j]:.3g}",
                     "fast": f"{np.nanmin(np.where(ok, t, np.nan)):.3g}",
                     "timing": str(wp["timing_mode"].values[i]) if "timing_mode" in wp else ""})
    return pd.DataFrame(rows)


# =============================================================================== LAMMPS
def lammps_section(lay: Layout, table: pd.DataFrame) -> None:
    """LAMMPS on the paper's microsphere exported as LAMMPS GRANULAR input, against microimpact.

    Examples
    --------
    A verification table of three impacts (a small made-up one: running LAMMPS is
    :func:`microimpact.studies.lammps_check.verify_lammps`), one of them beyond the tolerance; the
    section counts the agreements, gives the largest difference and shows no e_t for the head-on
    impact:

    >>> import pandas as pd
    >>> from microimpact.report.layout import Layout
    >>> table = pd.DataFrame({
    ...     "speed": [1.0, 1.0, 1.0], "incidence_deg": [0.0, 40.0, 80.0], "outcome_lammps": ["rebound"] * 3,
    ...     "e_n_microimpact": [0.9, 0.9, 0.9], "e_n_lammps": [0.9, 0.9, 0.9004],
    ...     "e_t_microimpact": [float("nan"), 0.8, 0.5], "e_t_lammps": [float("nan"), 0.8, 0.5],
    ...     "difference": [0.0, 2e-5, 4e-3], "step_error": [0.0, 1e-5, 2e-5], "agrees": [True, True, False],
    ...     "tolerance": 1e-3, "lammps_version": 20250722, "parameter_source": "export of the paper's microsphere"})
    >>> lay = Layout("Report")
    >>> lammps_section(lay, table)
    >>> paragraph = " ".join(lay.page.figure.texts[1].get_text().split())
    >>> "2 of 3 impacts agree within 0.001" in paragraph, "the largest difference is 0.004" in paragraph
    (True, True)
    >>> print(lay.page.figure.texts[-1].get_text().splitlines()[3])
    1           0         rebound     0.900000     0.900000     -            -            0.0e+00     0.0e+00
    """
    lay.section("LAMMPS GRANULAR on the exported contact", new_page=False, keep=2.5)
    first = table.iloc[0]
    n, agree = len(table), int(table["agrees"].astype(str).str.lower().eq("true").sum())
    captured = int((table["outcome_lammps"] == "capture").sum())
    lay.paragraph(
        f"The paper's microsphere in the laws LAMMPS can express (the force-controlled JKR break, no damping, its "
        f"friction coefficient through LAMMPS's tangential mindlin law with G* of the exported E and nu; "
        f"microimpact.io.lammps.lammps_expressible) was written as a fix wall/gran line "
        f"(results/lammps/contact.lmp) and run by LAMMPS {first.get('lammps_version', '?')} itself, one sphere "
        f"against the wall with fix nve/sphere, at 2000 and 4000 steps per contact time "
        f"(microimpact.studies.lammps_check). {agree} of {n} impacts agree within {float(first['tolerance']):g} "
        f"in e_n, the tangential restitution and the rebound spin ({captured} captured by both); the largest "
        f"difference is {float(table['difference'].max()):.2g} and LAMMPS's own largest step error (the two "
        f"runs apart) {float(table['step_error'].max()):.2g}. The paper's damping, ring adhesion and rigid "
        "tangential contact have no LAMMPS law (docs/guide/lammps.md).")
    lay.source(str(first.get("parameter_source", "?")))
    # the head-on and the two largest angles: the tangential law shows only off the normal
    angles = sorted(table["incidence_deg"].unique())
    rows = table[table["incidence_deg"].isin([angles[0], *angles[-2:]])]
    shown = pd.DataFrame({"speed": rows["speed"].map(lambda v: f"{v:.4g}"),
                          "angle": rows["incidence_deg"].map(lambda v: f"{v:g}"),
                          "outcome": rows["outcome_lammps"],
                          "mi": rows["e_n_microimpact"].map(lambda v: f"{v:.6f}"),
                          "lmp": rows["e_n_lammps"].map(lambda v: f"{v:.6f}"),
                          "t_mi": rows["e_t_microimpact"].map(_optional),
                          "t_lmp": rows["e_t_lammps"].map(_optional),
                          "diff": rows["difference"].map(lambda v: f"{v:.1e}"),
                          "step": rows["step_error"].map(lambda v: f"{v:.1e}")})
    lay.table(shown, {"speed": 10, "angle": 8, "outcome": 10, "mi": 11, "lmp": 11, "t_mi": 11, "t_lmp": 11,
                      "diff": 10, "step": 10},
              headers={"speed": "v [m/s]", "angle": "angle [deg]", "mi": "e_n micro.", "lmp": "e_n LAMMPS",
                       "t_mi": "e_t micro.", "t_lmp": "e_t LAMMPS", "diff": "difference", "step": "step error"},
              size=7.0)


def _optional(value) -> str:
    """A value of the table, or a dash where it has none (no tangential motion: head-on, captured)."""
    return "-" if pd.isna(value) else f"{float(value):.6f}"


# =============================================================================== stress sweep
def stress_section(lay: Layout, s: Mapping | None, settings: Mapping | None) -> None:
    """The seeded stress sweep of the engine: what was checked, the worst values, the failed cases.

    Examples
    --------
    A sweep of four cases, and a sweep switched off (the section says how to switch it on):

    >>> from microimpact.report.layout import Layout
    >>> from microimpact.studies.stress import stress_sweep
    >>> lay = Layout("Report")
    >>> stress_section(lay, stress_sweep(4, seed=0, reference_every=0).summary, {"cases": 4})
    >>> [t.get_text() for t in lay.page.figure.texts if t.get_text().startswith("Result")]
    ['Result: all 4 cases passed every check.']
    >>> off = Layout("Report")
    >>> stress_section(off, None, {"enabled": False})
    >>> "stress.enabled: false" in off.page.figure.texts[-1].get_text()
    True
    """
    lay.section("Numerical stability (stress sweep)", new_page=False, keep=2.5)
    settings = dict(settings or {})
    if s is None:
        lay.paragraph("The stress sweep was switched off in the configuration (stress.enabled: false); run "
                      "with --config 'stress={enabled: true}' to include it." if settings and not settings.get("enabled", True)
                      else "No stress-sweep summary was given to the report (results/stress_summary.json).")
        return
    lay.paragraph(_stress_intro(s, settings))
    lay.source(str(s.get("parameter_source", "random contacts drawn by microimpact.studies.stress.draw_cases "
                                                  "(no parameter set of the paper or of the fit)")))
    n, n_failed = int(s.get("cases_run", 0)), int(s.get("cases_failed", 0))
    by_kind = {k: int(v) for k, v in dict(s.get("failures_by_kind", {})).items()}
    if n_failed:
        kinds = ", ".join(f"{k} {v}" for k, v in by_kind.items() if v)
        lay.paragraph(f"Result: {n_failed} of {n} cases failed a check ({100 * n_failed / max(n, 1):.2g} %): {kinds}. "
                      "The failed cases are listed below; failures are reported, not hidden.", color="#b00000")
    else:
        lay.paragraph(f"Result: all {n} cases passed every check.")
    lay.heading("Checks: worst value over all cases and number of failed cases")
    lay.table(_stress_checks(s, settings, by_kind), {"check": 42, "tol": 12, "worst": 12, "case": 8, "failed": 8},
              headers={"tol": "tolerance", "worst": "worst", "case": "at case", "failed": "failed"}, size=7.2)
    ranges = dict(s.get("input_ranges", {}))
    if ranges:
        unknown = ("", "", "")
        t = pd.DataFrame([{"input": name, "symbol": STRESS_INPUTS.get(name, unknown)[0],
                           "units": STRESS_INPUTS.get(name, unknown)[1], "min": f"{float(lo):.3g}",
                           "max": f"{float(hi):.3g}", "drawn": STRESS_INPUTS.get(name, unknown)[2]}
                          for name, (lo, hi) in ranges.items()])
        lay.heading("Input ranges (SI units; angles in degrees)")
        lay.table(t, {"input": 18, "symbol": 14, "units": 8, "min": 9, "max": 9, "drawn": 46}, size=7.2)
    _stress_failures(lay, list(s.get("failed_cases", [])))


def _stress_intro(s: Mapping, settings: Mapping) -> str:
    n, n_ref, every = int(s.get("cases_run", 0)), int(s.get("reference_cases", 0)), settings.get("reference_every")
    ref_text = ((f"; {n_ref} cases" + (f" (every {every}-th)" if every else "")
                 + " also against the full 3-D reference solver (DOP853)") if n_ref
                else "; the 3-D reference solver was not run (stress.reference_every: 0)")
    zero = s.get("zero_probability")
    return (
        f"Seeded random stress sweep of the impact engine (microimpact.studies.stress.stress_sweep): {n} impacts drawn "
        f"with seed {s.get('seed', '?')} over the input ranges below, log-uniformly over decades where the range spans "
        "several, with exact zeros" + (f" (probability {float(zero):g})" if zero is not None else "")
        + " where zero is allowed. Each impact is simulated at rtol 1e-10 and 1e-8 and checked: no exception (the "
        "engine's step limit is its time box), finite results, 0 <= e_n <= 1 (e_n = 0 for a capture), the energy "
        "balance KE_in = KE_out + contact energy + dissipated energy, and agreement of the two tolerances" + ref_text
        + ". Errors are relative to the case's energy scale max(KE_in, depth of the contact well), velocities to the "
        f"matching speed scale (microimpact.studies.stress docstring). {int(s.get('captures', 0))} of the {n} impacts "
        f"were captured. The sweep took {float(s.get('seconds', math.nan)):.3g} s (slowest case "
        f"{float(s.get('slowest_case_seconds', math.nan)):.3g} s). Per-case inputs and results: results/stress.nc; "
        "summary with full-precision inputs: results/stress_summary.json; microimpact.studies.stress.draw_cases(n, "
        "seed) redraws the same cases.")


def _stress_checks(s: Mapping, settings: Mapping, by_kind: Mapping[str, int]) -> pd.DataFrame:
    tol = dict(s.get("tolerances", {}))
    n_ref = int(s.get("reference_cases", 0))
    limit = settings.get("case_time_limit")

    def worst(key):
        w = dict(s.get(key) or {})
        v, case = w.get("value"), (w.get("case") or {}).get("case")
        return ("" if v is None else f"{float(v):.3g}"), ("" if case is None else str(case))

    def tol_text(key):
        return f"<= {float(tol[key]):.0e}" if key in tol else ""

    rows = [
        {"check": "exception raised (incl. step limit)", "tol": "none", "kind": "exception"},
        {"check": "non-finite result", "tol": "none", "kind": "nonfinite"},
        {"check": "e_n outside [0, 1], or != 0 for a capture", "tol": "none", "kind": "restitution"},
        {"check": "energy balance", "tol": tol_text("energy"), "key": "worst_energy_error", "kind": "energy"},
        {"check": "convergence: rtol 1e-8 vs 1e-10", "tol": tol_text("convergence"), "key": "worst_convergence_error",
         "kind": "convergence"},
        {"check": f"engine vs reference solver ({n_ref} cases)", "tol": tol_text("reference"),
         "key": "worst_reference_error", "kind": "reference"},
        {"check": "time per case [s]", "tol": f"<= {float(limit):g}" if limit is not None else "", "kind": "timeout"},
    ]
    for r in rows:
        r["worst"], r["case"] = worst(r["key"]) if "key" in r else ("", "")
        if r["kind"] == "timeout":
            r["worst"] = f"{float(s.get('slowest_case_seconds', math.nan)):.3g}"
        if r["kind"] == "reference" and not n_ref:
            r["worst"] = "not run"
        r["failed"] = str(by_kind.get(r["kind"], 0)) if (r["kind"] != "reference" or n_ref) else "-"
    return pd.DataFrame(rows)


def _stress_failures(lay: Layout, failed: list) -> None:
    if not failed:
        return
    shown = failed[:STRESS_MAX_LISTED]
    rows = []
    for item in shown:
        inputs = dict(item.get("inputs", {}))
        row = {"case": str(inputs.get("case", "")),
               "checks": ", ".join(dict.fromkeys(f.get("kind", "?") for f in item.get("failures", [])))}
        for c in _FAILED_COLUMNS:
            if c not in row:
                v = inputs.get(c)
                row[c] = "" if v is None else f"{float(v) + 0.0:.3g}"  # + 0.0: no "-0"
        rows.append(row)
    lay.heading(f"Failed cases ({len(failed)}" + (f", first {len(shown)} listed" if len(shown) < len(failed) else "")
                + "): inputs, SI units")
    lay.table(pd.DataFrame(rows), _FAILED_COLUMNS, headers=_FAILED_HEADERS, size=7.0)
    details = [f"case {dict(item.get('inputs', {})).get('case', '?')}: {f.get('kind', '?')}: {f.get('detail', '')}"
               for item in shown for f in item.get("failures", [])]
    lay.paragraph("\n".join(details), mono=True, size=6.5)


# =============================================================================== configuration
def _plain(obj):
    """JSON fallback for numpy values and other objects in a configuration."""
    if isinstance(obj, np.generic):
        return obj.item()
    return obj.tolist() if isinstance(obj, np.ndarray) else str(obj)


def config_section(lay: Layout, config: Mapping) -> None:
    """The configuration the report was made with, as YAML.

    Examples
    --------
    >>> from microimpact.report.layout import Layout
    >>> lay = Layout("Report")
    >>> config_section(lay, {"data": "data/impacts.csv", "stress": {"cases": 10}})
    >>> lay.contents, lay.page.figure.texts[-1].get_text().splitlines()
    ([('1. Appendix: configuration', 0)], ['data: data/impacts.csv', 'stress:', '  cases: 10'])
    """
    lay.section("Appendix: configuration", new_page=False, keep=1.5)
    lay.paragraph("The configuration this report was made with (workflow/config/config.yaml merged with "
                  "command-line overrides), validated against workflow/schemas/config.schema.yaml.")
    plain = json.loads(json.dumps(dict(config), default=_plain))
    lay.paragraph(yaml.safe_dump(plain, sort_keys=False, width=110), mono=True, size=7)
