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
               "impacts replaces. " + "; ".join(parts) + ".")
    return Plot(fig, caption)


def _rows_table(record: Mapping) -> pd.DataFrame:
    rows = pd.DataFrame(list(record["rows"]))
    if rows.empty:
        return rows
    return pd.DataFrame({"id": rows["id"], "d [um]": [f"{2e6 * r:.3g}" for r in rows["radius"]],
                         "speed [m/s]": [f"{v:.3g}" for v in rows["speed"]],
                         "angle [deg]": [f"{a:.3g}" for a in rows["incidence_deg"]],
                         "e_n expected": [f"{e:.3f}" for e in rows["e_n_expected"]], "reason": rows["reason"]})


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
        + (f" (friction: {', '.join(f'{a:g}' for a in space.get('oblique_deg', []))} deg, e_t measured to "
           f"{space.get('e_t_sigma', float('nan')):.3g})" if "friction" in record["parameters"] else "")
        + f", with e_n measured to {space.get('e_n_sigma', float('nan')):.3g}. Criterion: {record['criterion']}. "
        "No impact is recommended "
        "where the parameter has no effect (a captured impact for the damping; one that ends rolling for friction). "
        "microimpact design fit.nc --out design.csv writes the same rows as a measured-impact CSV template; "
        "measured, they are appended to the data and refitted.")
    for p, note in record.get("notes", {}).items():
        lay.paragraph(f"{p}: {note}.")
    table = _rows_table(record)
    if not table.empty:
        lay.table(table, {"id": 10, "d [um]": 6, "speed [m/s]": 7, "angle [deg]": 6, "e_n expected": 8, "reason": 60},
                  size=6.5)
    if record.get("widths"):
        lay.plot(plot_design_widths(record), max_height=2.8)
