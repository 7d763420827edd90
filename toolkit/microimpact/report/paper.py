"""Part B of the report: the reproduction of Cheng, Brach & Dunn (2002) with the paper's parameters.

Sections: the nonlinear dynamics of the normal contact (Figs. 4, 5), the phase portraits, the
Table 2 sweeps (Figs. 7-14) and the table of the paper's numbers and statements. Each section
states the ``parameter_source`` of the files it shows (``preset: <name>`` or ``config``).
"""

from __future__ import annotations

import math

import pandas as pd
import xarray as xr

from microimpact.report import figures
from microimpact.report.inputs import parameter_source
from microimpact.report.layout import Layout

__all__ = ["dynamics_section", "portraits_section", "paper_sweeps_section", "reproduction_section"]


def dynamics_section(lay: Layout, bif: xr.Dataset | None, dyn: xr.Dataset | None) -> None:
    """The (C1, C2) plane (Fig. 4) and the damping and equilibrium at the phase-portrait speeds.

    Examples
    --------
    The 1990 wall sphere's scales (m, X, T of Eqs. (29)-(30)) in the section's first paragraph:

    >>> from microimpact.dynamics.nonlinear import bifurcation_plane, dynamics_summary
    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.report.layout import Layout
    >>> lay = Layout("Report")
    >>> dynamics_section(lay, bifurcation_plane(n_c1=21, n_c2=21), dynamics_summary(WALL_1990, [1.0, 2.0]))
    >>> text = " ".join(t.get_text() for t in lay.page.figure.texts)
    >>> "m = 2.322e-13 kg, X = 2.626e-08 m" in text
    True
    """
    lay.section("Nonlinear dynamics of the normal contact (Figs. 4, 5)")
    if dyn is not None:
        lay.source(parameter_source(dyn))
        a = dyn.attrs
        lay.paragraph(
            f"Contact: r = {float(a.get('contact_radius', math.nan)) * 1e6:.3g} um, "
            f"f0 = {float(a.get('contact_adhesion_line_force', math.nan)):.4g} N/m, "
            f"zeta_H = {float(a.get('contact_zeta_hertz', math.nan)):.3g}, "
            f"zeta_A = {float(a.get('contact_zeta_adhesion', math.nan)):.3g}; "
            f"m = {float(dyn['mass']):.4g} kg, X = {float(dyn['length_scale']):.4g} m, "
            f"T = {float(dyn['time_scale']):.4g} s. Critical velocity v_c (C = 2, Eq. (38)) = "
            f"{float(dyn['critical_velocity']):.4g} m/s; normal capture velocity = "
            f"{float(dyn['capture_velocity']):.4g} m/s.")
    if bif is not None:
        lay.plot(figures.plot_bifurcation_plane(bif), max_height=4.2)
    if dyn is not None:
        lay.heading("Damping and equilibrium at the phase-portrait speeds")
        lay.table(_equilibria(dyn), {"speed": 14, "C1": 10, "C2": 10, "C": 10, "type": 14, "omega_f": 22},
                  headers={"speed": "v_n [m/s]", "C1": "C1 [-]", "C2": "C2 [-]", "C": "C [-]",
                           "type": "equilibrium", "omega_f": "omega_f [rad/s]"}, size=7.2)


def _equilibria(dyn: xr.Dataset) -> pd.DataFrame:
    return pd.DataFrame({
        "speed": [f"{v:.3g}" for v in dyn["speed"].values],
        "C1": [f"{x:.4g}" for x in dyn["C1"].values],
        "C2": [f"{x:.4g}" for x in dyn["C2"].values],
        "C": [f"{x:.4g}" for x in dyn["C"].values],
        "type": [str(x) for x in dyn["equilibrium_type"].values],
        "omega_f": [f"{x:.4g}" if math.isfinite(x) and c < 2 else "none (C >= 2)"
                    for x, c in zip(dyn["asymptotic_frequency"].values, dyn["C"].values)],
    })


def portraits_section(lay: Layout, portraits: list[xr.Dataset]) -> None:
    """Phase portraits (Fig. 5), at most two panels per figure (four on a page width are unreadable).

    Examples
    --------
    Three portraits take two figures (at most two panels each):

    >>> from microimpact.dynamics.nonlinear import phase_portraits
    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.report.layout import Layout
    >>> lay = Layout("Report")
    >>> portraits_section(lay, phase_portraits(WALL_1990, [1.0, 2.0, 4.0]))
    >>> lay.contents, len(lay.page.figure.axes)
    ([('1. Phase portraits (analogue of Fig. 5)', 0)], 2)
    """
    lay.section("Phase portraits (analogue of Fig. 5)", new_page=False, keep=3.6)
    lay.source(parameter_source(*portraits))
    for i in range(0, len(portraits), 2):
        lay.plot(figures.plot_phase_portraits(portraits[i:i + 2]), max_height=4.0)


def paper_sweeps_section(lay: Layout, sweeps: list[xr.Dataset]) -> None:
    """The Table 2 cases (Figs. 7-14), one page per case.

    Examples
    --------
    Case 2.1 on a small grid: its subsection and its two figures (energy loss, Fig. 7; restitution
    and impulse ratios, Fig. 8):

    >>> from microimpact.presets import WALL_1990
    >>> from microimpact.report.layout import Layout
    >>> from microimpact.studies.sweeps import case_spec, run_sweep
    >>> sweep = run_sweep(WALL_1990, case_spec("2.1", {"speed": [2.0, 4.0], "incidence_deg": [0.0, 30.0]}), case="2.1")
    >>> lay = Layout("Report")
    >>> paper_sweeps_section(lay, [sweep])
    >>> lay.contents, len(lay.page.figure.axes)
    ([('1. Sensitivity to the initial conditions (Table 2, Figs. 7-14)', 0), ('1.1 Table 2 case 2.1 (Figs. 7, 8)', 0)], 2)
    """
    lay.section("Sensitivity to the initial conditions (Table 2, Figs. 7-14)")
    lay.paragraph(
        "Each Table 2 case is swept over the incident speed and one curve-family parameter with the fast "
        "engine (one normal solve per distinct normal speed, closed-form tangential map). Curves: rebound "
        "solid, captured dotted; grey bands mark capture.")
    number = lay.number
    for k, ds in enumerate(sorted(sweeps, key=lambda d: str(d.attrs.get("case", "")))):
        case = str(ds.attrs.get("case", "?"))
        figs = [f for f in figures.TABLE2_FIGURES.get(case, (None, None)) if f]
        nums = f" (Fig{'s' if len(figs) > 1 else ''}. {', '.join(figs)})" if figs else ""
        lay.section(f"{number}.{k + 1} Table 2 case {case}{nums}", new_page=k > 0, numbered=False)
        lay.source(parameter_source(ds))
        if ds.attrs.get("case_description"):
            lay.paragraph(str(ds.attrs["case_description"]) + ".")
        if figures.TABLE2_FIGURES.get(case, (None, None))[0] is not None:
            lay.plot(figures.plot_energy_loss(ds), max_height=3.6)
        lay.plot(figures.plot_restitution_and_impulse(ds), max_height=4.2)


def reproduction_section(lay: Layout, repro: pd.DataFrame, path=None) -> None:
    """The paper's numbers and statements against the toolkit's, with agreement.

    One block per claim in the body font (the claim, the paper's value, the toolkit's, the note),
    not a table of wrapped monospace cells; the full table is the CSV the section names.

    Examples
    --------
    >>> from microimpact.report.layout import Layout
    >>> from microimpact.studies.reproduction import reproduction_table
    >>> repro = reproduction_table()
    >>> lay = Layout("Report")
    >>> reproduction_section(lay, repro, path="results/paper/reproduction.csv")
    >>> text = " ".join(" ".join(t.get_text().split()) for p in lay.pages for t in p.figure.texts)
    >>> f"{len(repro)} rows: {int((repro['agree'] == True).sum())} agree" in text
    True
    >>> "results/paper/reproduction.csv" in text
    True
    """
    lay.section("Reproduction of the paper's numbers and statements", new_page=False, keep=1.5)
    agree = repro["agree"].astype(str).str.lower()
    n_yes = int(agree.isin(["true", "yes"]).sum())
    no = agree.isin(["false", "no"])
    where = str(path) if path is not None else "the reproduction CSV of the pipeline"
    lay.paragraph(
        f"Every toolkit value is computed when the pipeline runs (microimpact.studies.reproduction). {len(repro)} rows: "
        f"{n_yes} agree, {int(no.sum())} disagree"
        + (f" ({', '.join(str(x) for x in repro.loc[no, 'id'])})" if no.any() else "")
        + f", {len(repro) - n_yes - int(no.sum())} not checkable (the paper's figures are missing from the available "
        f"text). Disagreements are reported, not tuned away. The full table (appendix, every column): {where}.")
    if "parameter_source" in repro:
        lay.source("; ".join(dict.fromkeys(str(s) for s in repro["parameter_source"])))
    else:
        lay.source("the paper's Table 1 (each row of the table names the parameter set it uses)")
    verdicts = agree.map({"true": "agrees", "false": "DISAGREES", "yes": "agrees", "no": "DISAGREES"})
    for (_, row), verdict in zip(repro.iterrows(), verdicts):
        cell = lambda key: "" if key not in row or pd.isna(row[key]) else str(row[key])  # noqa: E731
        lay.paragraph(f"{cell('id')} ({cell('source')}): {verdict if isinstance(verdict, str) else 'not checkable'}."
                      f" {cell('claim')}", size=8.0, gap=0.0,
                      color="#b00000" if verdict == "DISAGREES" else "black")
        lines = [f"paper: {cell('paper_value')}", f"toolkit: {cell('toolkit_value')}"]
        if cell("note"):
            lines.append(f"note: {cell('note')}")
        lay.paragraph("\n".join(lines), size=7.4, gap=0.1, color="0.25")
