"""The report's figures as an analyst reads them: no legend over data, the bifurcation plane readable
on a log C1 axis, one name per quantity (capture velocity v_capture against the critical velocity
v_c of Eq. (38)), diameters in every legend, and no '(fixed)' for a fitted parameter.

The overlap check works from the figure's artists: after drawing, the legend's bounding box in
display coordinates must contain no point of any line or collection drawn in data coordinates
(reference lines such as axhline live in axes coordinates and are not data). A legend outside the
axes passes by construction, a legend placed inside over the points fails.
"""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
import xarray as xr  # noqa: E402
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.collections import LineCollection, PathCollection  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from microimpact.analysis.fitting import fit_damping  # noqa: E402
from microimpact.analysis.kharaz import kharaz_comparison  # noqa: E402
from microimpact.analysis.synthetic import write_synthetic_impacts  # noqa: E402
from microimpact.dynamics.nonlinear import bifurcation_plane, phase_portraits  # noqa: E402
from microimpact.io import default_materials_path, read_impacts, read_materials  # noqa: E402
from microimpact.presets import WALL_1990  # noqa: E402
from microimpact.report import figures  # noqa: E402
from microimpact.report.models import plot_model_comparison  # noqa: E402
from microimpact.studies.material import material_dynamics, material_sweep  # noqa: E402
from microimpact.studies.sweeps import case_spec, restitution_curves  # noqa: E402


def _densify(xy: np.ndarray, n: int = 20) -> np.ndarray:
    """Points along the segments of a polyline in display space (a line crossing a legend counts)."""
    if len(xy) < 2:
        return xy
    t = np.linspace(0.0, 1.0, n)[:, None, None]
    return (xy[:-1][None] * (1 - t) + xy[1:][None] * t).reshape(-1, 2)


def _data_points(ax) -> list[tuple[str, np.ndarray]]:
    """(artist label, display-space points) of every artist drawn in data coordinates on ``ax``."""
    out = []
    for line in ax.get_lines():
        if line.get_transform() != ax.transData or not line.get_visible():
            continue
        xy = np.asarray(line.get_xydata(), float)
        xy = xy[np.isfinite(xy).all(axis=1)]
        if xy.size:
            disp = ax.transData.transform(xy)
            out.append((line.get_label(), _densify(disp) if line.get_linestyle() not in ("None", "none", "") else disp))
    for coll in ax.collections:
        if isinstance(coll, LineCollection):
            for seg in coll.get_segments():
                seg = np.asarray(seg, float)
                seg = seg[np.isfinite(seg).all(axis=1)]
                if seg.size:
                    out.append((coll.get_label(), _densify(coll.get_transform().transform(seg))))
        elif isinstance(coll, PathCollection):
            off = np.asarray(coll.get_offsets(), float)
            if off.size:
                out.append((coll.get_label(), coll.get_offset_transform().transform(off)))
    return out


def legend_overlaps(fig: Figure) -> list[str]:
    """Which data artists lie under a legend of ``fig`` (empty when none do)."""
    FigureCanvasAgg(fig).draw()
    renderer = fig.canvas.get_renderer()
    found = []
    legends = [(ax, ax.get_legend()) for ax in fig.axes] + [(ax, leg) for leg in fig.legends for ax in fig.axes]
    for ax, leg in legends:
        if leg is None:
            continue
        box = leg.get_window_extent(renderer)
        clip = ax.get_window_extent(renderer)
        for label, pts in _data_points(ax):
            inside = ((pts[:, 0] > box.x0) & (pts[:, 0] < box.x1) & (pts[:, 1] > box.y0) & (pts[:, 1] < box.y1)
                      & (pts[:, 0] >= clip.x0) & (pts[:, 0] <= clip.x1) & (pts[:, 1] >= clip.y0) & (pts[:, 1] <= clip.y1))
            if inside.any():
                found.append(f"{ax.get_title(loc='left') or ax.get_ylabel()}: {label}")
    return found


def test_the_overlap_check_can_fail():
    # a legend placed over the points must be found
    fig = Figure(figsize=(3, 2))
    ax = fig.subplots()
    ax.plot(np.linspace(0, 1, 50), np.full(50, 0.95), "o", label="data")
    ax.set_ylim(0, 1)
    ax.legend(loc="upper right")
    assert legend_overlaps(fig) == ["data"] or legend_overlaps(fig)[0].endswith("data")
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0))
    assert legend_overlaps(fig) == []


@pytest.fixture(scope="module")
def fit_ds(tmp_path_factory):
    path = tmp_path_factory.mktemp("fig") / "two.csv"
    material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    table = read_impacts(write_synthetic_impacts(path, radii=(1.72e-6, 3.45e-6), n_per_radius=6, seed=3))
    return fit_damping(table, material, confidence_intervals=False).to_dataset()


def test_no_legend_over_data_kharaz():
    plot = figures.plot_kharaz(kharaz_comparison(fit_friction=False, curve_incidence_deg=np.arange(1.0, 80.0, 8.0)))
    assert legend_overlaps(plot.figure) == []


def test_no_legend_over_data_fit_and_sizes(fit_ds):
    plots = [figures.plot_fit(fit_ds, restitution_curves(fit_ds, [1.0, 3.0, 10.0, 30.0])),
             figures.plot_size_dependence(
                 material_sweep(fit_ds, case_spec("2.1", {"speed": {"start": 1, "stop": 30, "num": 6},
                                                          "incidence_deg": [0.0]}), case="2.1"),
                 material_dynamics(fit_ds))]
    for plot in plots:
        assert legend_overlaps(plot.figure) == [], plot.caption[:60]


def test_no_legend_over_data_paper_figures():
    plots = [figures.plot_phase_portraits(phase_portraits(WALL_1990, [0.5, 1e-5])),
             figures.plot_bifurcation_plane(bifurcation_plane(n_c1=21, n_c2=21))]
    for plot in plots:
        assert legend_overlaps(plot.figure) == [], plot.caption[:60]


def test_bifurcation_plane_spreads_the_points_on_a_log_c1_axis():
    ds = bifurcation_plane(n_c1=21, n_c2=21)
    ax = figures.plot_bifurcation_plane(ds).figure.axes[0]
    assert ax.get_xscale() == "log"
    lo, hi = ax.get_xlim()
    c1 = ds["case_C1"].values
    # every point sits inside the axis, and the points span a visible share of it (on the linear axis
    # to C1 = 6 they all fell within 2 % of its width)
    assert lo < c1.min() and c1.max() < hi
    share = (np.log10(c1.max()) - np.log10(c1.min())) / (np.log10(hi) - np.log10(lo))
    assert share > 0.2


def test_capture_velocity_and_critical_velocity_have_different_names(fit_ds):
    sweep = material_sweep(fit_ds, case_spec("2.1", {"speed": {"start": 1, "stop": 30, "num": 6},
                                                     "incidence_deg": [0.0, 40.0]}), case="2.1")
    one = sweep.isel(radius=0)
    one.attrs = {k: (v[0] if isinstance(v, np.ndarray) and v.size > 1 else v) for k, v in one.attrs.items()}
    caption = figures.plot_restitution_and_impulse(one).caption
    assert "v_capture" in caption and "v_c " not in caption and "v_c =" not in caption
    size = figures.plot_size_dependence(sweep, material_dynamics(fit_ds))
    labels = [t.get_text() for t in size.figure.axes[1].get_legend().get_texts()]
    assert any("v_{capture}" in t for t in labels) and any("v_c" in t and "38" in t for t in labels)


def test_legends_name_diameters_and_the_fitted_parameters_are_not_fixed(fit_ds):
    plot = figures.plot_fit(fit_ds)
    texts = [t.get_text() for t in plot.figure.axes[0].get_legend().get_texts()]
    radii = sorted({round(2e6 * r, 3) for r in fit_ds["radius"].values})
    assert [f"d = {d:.3g} µm" for d in radii] == [t for t in texts if t.startswith("d = ")]
    varied = fit_ds.attrs["varied"].split()
    assert "zeta_hertz" in varied
    # zeta_H was fitted: the caption never calls it fixed; w_A (not varied) is the materials config's
    assert "zeta_H = " in plot.caption and "zeta_H = " + plot.caption.split("zeta_H = ")[1].split(",")[0]
    assert "(fixed" not in plot.caption.split("zeta_H = ")[1].split("zeta_A")[0]
    if "work_of_adhesion" not in varied:
        assert "(fixed, materials config)" in plot.caption.split("w_A = ")[1]
    stripped = fit_ds.copy()
    stripped["zeta_hertz_stderr"] = np.nan  # a fitted parameter without a standard error is still fitted
    assert "(fixed" not in figures.plot_fit(stripped).caption.split("zeta_H = ")[1].split("zeta_A")[0]
