"""Report page: what to measure next (the experiment design of the analyst's fit, issue 54).

Reads the ``design.json`` of the pipeline's ``design`` rule (:func:`microimpact.analysis.design.design_record`
of :func:`~microimpact.analysis.design.design_impacts`, and of
:func:`~microimpact.analysis.design.design_friction` when friction is named); no model is run here.
The page states the criterion and the identifiability notes, lists the recommended impacts with the
reason for each, and draws the expected 95 % interval width of each parameter against the number
of new impacts, recommended against uniform.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from microimpact.report.figures import WIDTH, Plot, _figure, _rc
from microimpact.report.layout import Layout

__all__ = ["design_section", "plot_design_widths"]

_LABELS = {"zeta_hertz": r"$\zeta_H$ [-]", "zeta_adhesion": r"$\zeta_A$ [-]", "work_of_adhesion": r"$w_A$ [J/m$^2$]",
           "friction": "f [-]"}


@_rc
def plot_design_widths(record: Mapping) -> Plot:
    """Expected 95 % interval width of each designed parameter after 0 ... N new impacts.

    Parameters
    ----------
    record : mapping
        :func:`~microimpact.analysis.design.design_record` output.

    Examples
    --------
    >>> rec = {"widths": [{"n_new": k, "parameter": "zeta_hertz", "design": 1 / (1 + k), "uniform": 1 / (1 + k / 2)}
    ...                   for k in range(4)], "rows": [], "criterion": "Fisher"}
    >>> plot = plot_design_widths(rec)
    >>> [line.get_label() for line in plot.figure.axes[0].get_lines()]
    ['recommended', 'uniform']
    >>> "0.25 after 3 recommended impacts, 0.4 after as many uniform ones" in plot.caption
    True
    """
    widths = pd.DataFrame(list(record["widths"]))
    params = list(dict.fromkeys(widths["parameter"]))
    fig = _figure(WIDTH * 0.9, 2.6)
    axes = np.atleast_1d(fig.subplots(1, len(params)))
    parts = []
    for ax, p in zip(axes, params):
        w = widths[widths["parameter"] == p].sort_values("n_new")
        ax.plot(w["n_new"], w["design"], "o-", ms=3, lw=1.1, color="C0", label="recommended")
        ax.plot(w["n_new"], w["uniform"], "s--", ms=3, lw=1.1, color="C1", label="uniform")
        ax.set_yscale("log")
        ax.set_xlabel("new impacts")
        ax.set_ylabel("expected 95 % width of " + _LABELS.get(p, p))
        last = w.iloc[-1]
        parts.append(f"{p}: {w['design'].iloc[0]:.3g} now, {last['design']:.3g} after {int(last['n_new'])} recommended "
                     f"impacts, {last['uniform']:.3g} after as many uniform ones")
    axes[0].legend(frameon=False)
    caption = ("Expected 95 % interval width (log scale) of each parameter against the number of new impacts, for the "
               "recommended impacts in the order chosen (solid) and for the same number spread uniformly over the "
               "same space (dashed); an expectation (" + record.get("criterion", "") + ") that the refit of the measured "
               "impacts replaces. " + "; ".join(parts) + "."
               + (" The friction panel is the width at the centre of the friction range; the recommended oblique "
                  "impacts minimise its mean over the whole range (f unknown), so at the centre alone a uniform set "
                  "can come out narrower." if "friction" in params else ""))
    return Plot(fig, caption)


def _rows_table(record: Mapping) -> pd.DataFrame:
    """The recommended impacts, a run of repeats of one impact (same size, speed and angle, chosen one
    after another) as one line with its count and the reason of its first: a design that repeats the
    most informative impact 20 times is one line, not 20 (the CSV template keeps every row).

    Examples
    --------
    >>> rows = [{"id": f"design-00{k}", "radius": 1e-6, "speed": 2.0 if k < 3 else 4.0, "incidence_deg": 0.0,
    ...          "e_n_expected": 0.5, "reason": f"r{k}"} for k in (1, 2, 3)]
    >>> _rows_table({"rows": rows})[["id", "n", "reason"]].values.tolist()
    [['design-001..002', '2', 'r1'], ['design-003', '1', 'r3']]
    """
    rows = pd.DataFrame(list(record["rows"]))
    if rows.empty:
        return rows
    key = rows[["radius", "speed", "incidence_deg"]]
    run = (key != key.shift()).any(axis=1).cumsum()
    groups = [g for _, g in rows.groupby(run, sort=False)]
    first = pd.DataFrame([g.iloc[0] for g in groups])
    ids = [g["id"].iloc[0] if len(g) == 1 else f"{g['id'].iloc[0]}..{str(g['id'].iloc[-1]).rsplit('-', 1)[-1]}"
           for g in groups]
    return pd.DataFrame({"id": ids, "n": [str(len(g)) for g in groups],
                         "d [um]": [f"{2e6 * r:.3g}" for r in first["radius"]],
                         "speed [m/s]": [f"{v:.3g}" for v in first["speed"]],
                         "angle [deg]": [f"{a:.3g}" for a in first["incidence_deg"]],
                         "e_n expected": [f"{e:.3f}" for e in first["e_n_expected"]],
                         "reason": list(first["reason"])})


def _oblique_text(space: Mapping) -> str:
    """'rebound angle measured to 1 deg' from a design record's space (e_t for records without the key)."""
    q = space.get("oblique_quantity", "tangential_restitution")
    if q == "none":
        return "e_n only: nothing determines f"
    unit = {"tangential_restitution": "", "rebound_angle": " deg", "rebound_spin": " rad/s"}.get(q, "")
    sigma = space.get("oblique_sigma", space.get("e_t_sigma", float("nan")))
    return f"{q.replace('_', ' ')} measured to {sigma:.3g}{unit}"


def design_section(lay: Layout, record: Mapping) -> None:
    """The page "What to measure next": criterion, notes, the recommended impacts, the width figure.

    Examples
    --------
    >>> from microimpact.report.layout import Layout
    >>> rec = {"criterion": "Fisher information", "parameters": ["zeta_hertz"], "notes": {"zeta_hertz": "upper bound"},
    ...        "space": {"speed_range": [0.5, 20.0], "radii": [3.45e-6], "incidence_deg": [0.0], "e_n_sigma": 0.02},
    ...        "rows": [{"id": "design-001", "radius": 3.45e-6, "speed": 20.0, "incidence_deg": 0.0,
    ...                  "e_n_expected": 0.62, "reason": "v_n = 20 m/s"}],
    ...        "widths": [{"n_new": k, "parameter": "zeta_hertz", "design": 1.0 / (1 + k), "uniform": 1.0} for k in (0, 1)],
    ...        "source": "fit.nc"}
    >>> lay = Layout("Report")
    >>> design_section(lay, rec)
    >>> text = " ".join(t.get_text() for t in lay.page.figure.texts)
    >>> "What to measure next" in text, "design-001" in text, "upper bound" in text
    (True, True, True)
    """
    lay.section("What to measure next")
    space = record.get("space", {})
    radii = ", ".join(f"{2e6 * r:.3g}" for r in space.get("radii", []))
    lo, hi = space.get("speed_range", [float("nan")] * 2)
    lay.paragraph(
        f"The next {len(record['rows'])} impacts that most narrow the intervals of "
        f"{', '.join(record['parameters'])} given the fit ({record.get('source', 'the damping fit')}), chosen one at a "
        f"time from candidates at the measured sphere diameters ({radii} um), incident speeds {lo:.3g}-{hi:.3g} m/s "
        f"and incidence angles {', '.join(f'{a:g}' for a in space.get('incidence_deg', []))} deg"
        + (f" (friction: {', '.join(f'{a:g}' for a in space.get('oblique_deg', []))} deg, "
           f"{_oblique_text(space)})" if "friction" in record["parameters"] else "")
        + f", with e_n measured to {space.get('e_n_sigma', float('nan')):.3g}. Criterion: {record['criterion']}. "
        "No impact is recommended "
        "where the parameter has no effect (a captured impact for the damping; one that ends rolling for friction). "
        "A run of repeats of one impact is one line of the table below (n: how many). microimpact design fit.nc "
        "--out design.csv writes the same rows as a measured-impact CSV template; measured, they are appended to "
        "the data and refitted.")
    for p, note in record.get("notes", {}).items():
        lay.paragraph(f"{p}: {note}.")
    table = _rows_table(record)
    if not table.empty:
        lay.table(table, {"id": 14, "n": 3, "d [um]": 6, "speed [m/s]": 7, "angle [deg]": 6, "e_n expected": 8,
                          "reason": 58}, size=6.5)
    if record.get("widths"):
        lay.plot(plot_design_widths(record), max_height=2.8)
