"""Figure functions: they return labelled matplotlib Figures with captions and save to PDF."""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402
import xarray as xr  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from microimpact import presets  # noqa: E402
from microimpact.studies import sweeps  # noqa: E402
from microimpact.dynamics import nonlinear as dynamics
from microimpact.report import figures as plots

C = presets.WALL_1990
SPEEDS = [0.5, 1.2, 1.6, 3.0, 10.0]


@pytest.fixture(scope="module")
def sweep23():
    spec = dict(sweeps.TABLE2_CASES["2.3"], speed=SPEEDS, incidence_deg=[0.0, 30.0])
    return sweeps.run_sweep(C, spec, case="2.3")


@pytest.fixture(scope="module")
def sweep22():
    spec = dict(sweeps.TABLE2_CASES["2.2"], speed=SPEEDS, omega_tp=[0.0, 1.8e5])
    return sweeps.run_sweep(C, spec, case="2.2", capture_speed=False)


def axes_with_data(fig):
    return [ax for ax in fig.axes if ax.lines or ax.collections]


def check(plot, tmp_path, name, units=("[",)):
    assert isinstance(plot, plots.Plot)
    assert isinstance(plot.figure, Figure)
    assert len(plot.caption) > 40
    for ax in axes_with_data(plot.figure):
        for label in (ax.get_xlabel(), ax.get_ylabel()):
            assert label, f"{name}: unlabelled axis"
            assert any(u in label for u in units), f"{name}: no unit in {label!r}"
    path = tmp_path / f"{name}.pdf"
    plot.figure.savefig(path)
    assert path.read_bytes()[:5] == b"%PDF-"
    return plot


def test_energy_loss(sweep23, tmp_path):
    p = check(plots.plot_energy_loss(sweep23), tmp_path, "fig11")
    assert p.paper_figure == "11"
    ax = p.figure.axes[0]
    assert "[-]" in ax.get_ylabel() and "[m/s]" in ax.get_xlabel()
    legend = p.figure.axes[2].get_legend()
    assert legend is not None and "deg" in legend.get_title().get_text()
    assert "1.45" in p.caption  # capture velocity is stated (and marked)


def test_restitution_and_impulse_gaps_below_capture(sweep23, tmp_path):
    p = check(plots.plot_restitution_and_impulse(sweep23), tmp_path, "fig12")
    assert p.paper_figure == "12"
    assert len(axes_with_data(p.figure)) == 3  # e_n, mu_t, mu_t'
    mu_ax = p.figure.axes[1]
    y = mu_ax.lines[0].get_ydata()
    # captured impacts (0.5 and 1.2 m/s) are gaps, not zeros
    assert np.isnan(y[:2]).all() and np.isfinite(y[2:]).all()


def test_in_plane_sweep_drops_the_zero_panel(sweep22, tmp_path):
    # case 2.2 spins about t' only: mu_t' is 0 throughout and is left out (said in the caption)
    p = check(plots.plot_restitution_and_impulse(sweep22), tmp_path, "fig10")
    assert len(axes_with_data(p.figure)) == 2
    assert "not shown" in p.caption
    check(plots.plot_energy_loss(sweep22), tmp_path, "fig9")  # capture estimated from the grid


def test_two_curve_dimensions_need_a_selection():
    spec = {"speed": [1.6, 3.0], "incidence_deg": [0.0, 10.0], "friction": [0.1, 0.2]}
    ds = sweeps.run_sweep(C, spec, capture_speed=False)
    with pytest.raises(ValueError, match="several dimensions"):
        plots.plot_energy_loss(ds)
    plots.plot_energy_loss(ds.sel(friction=0.1))


def test_phase_portraits(tmp_path):
    portraits = [dynamics.phase_portrait(C, v, rtol=1e-8) for v in (0.5, 1e-5)]
    p = check(plots.plot_phase_portraits(portraits), tmp_path, "fig5")
    assert "capture with oscillation" in p.caption and "capture without oscillation" in p.caption


def test_bifurcation_plane(tmp_path):
    ds = dynamics.bifurcation_plane(n_c1=41, n_c2=41)
    p = check(plots.plot_bifurcation_plane(ds), tmp_path, "fig4", units=("[-]",))
    assert "C = 2" in p.caption or "C > 2" in p.caption


def fit_dataset():
    """Hand-built dataset with the layout of fitting.DampingFit.to_dataset() (no fit run)."""
    rng = np.random.default_rng(0)
    radius = np.repeat([1.29e-6, 3.45e-6], 6)
    v = np.tile(np.geomspace(2, 60, 6), 2)
    e_model = 0.7 * (1 - np.exp(-v / 5 / (radius / 3.45e-6) ** -1))
    ds = xr.Dataset(
        {
            "radius": ("point", radius, {"units": "m", "long_name": "sphere radius"}),
            "normal_speed": ("point", v, {"units": "m s-1", "long_name": "incident normal speed"}),
            "e_n_measured": ("point", e_model + rng.normal(0, 0.02, v.size), {"units": "1", "long_name": "measured"}),
            "sigma": ("point", np.full(v.size, 0.02), {"units": "1", "long_name": "uncertainty"}),
            "e_n_model": ("point", e_model, {"units": "1", "long_name": "model"}),
            "zeta_hertz": ((), 0.5, {"units": "1"}),
            "zeta_hertz_stderr": ((), 0.05, {"units": "1"}),
            "zeta_adhesion": ((), 29.0, {"units": "1"}),
            "zeta_adhesion_stderr": ((), 0.2, {"units": "1"}),
            "work_of_adhesion": ((), 0.216, {"units": "J m-2"}),
            "work_of_adhesion_stderr": ((), np.nan, {"units": "J m-2"}),
        },
        attrs={"redchi": 1.1, "fit_source": "synthetic_impacts.csv", "varied": "zeta_hertz zeta_adhesion"},
    )
    ds["residual"] = ("point", (ds["e_n_model"].values - ds["e_n_measured"].values) / 0.02, {"units": "1"})
    return ds


def test_fit(tmp_path):
    p = check(plots.plot_fit(fit_dataset()), tmp_path, "fig3")
    # w_A was not varied (the file's 'varied' list): the caption says it is the materials config's
    assert "SYNTHETIC" in p.caption and "w_A = 0.216 (fixed, materials config)" in p.caption
    assert len(p.figure.axes[0].get_legend().get_texts()) == 4  # 2 sizes + data + model
    # the residual panel under the fit (issue 25): every point's (model - measured)/sigma, as in the file
    ds = fit_dataset()
    drawn = np.sort(np.concatenate([line.get_ydata() for line in p.figure.axes[1].get_lines()
                                    if line.get_marker() == "o"]))
    np.testing.assert_allclose(drawn, np.sort(ds["residual"].values), rtol=1e-12)
    assert "residuals" in p.caption


def test_work_precision(tmp_path):
    ds = xr.Dataset(
        {
            "time_per_impact": (("method", "setting"), [[1e-5, 2e-5], [1e-3, 4e-3]], {"units": "s"}),
            "max_error_e_n": (("method", "setting"), [[1e-5, 1e-8], [1e-4, np.nan]], {"units": "1"}),
            "max_error_mu": (("method", "setting"), [[1e-5, 1e-8], [1e-4, 1e-9]], {"units": "1"}),
        },
        coords={"method": ["engine", "reference"], "setting": ["1e-6", "1e-9"]},
    )
    p = check(plots.plot_work_precision(ds), tmp_path, "work_precision")
    ax = p.figure.axes[0]
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"


def test_kharaz(tmp_path):
    import pandas as pd

    from microimpact.analysis.kharaz import kharaz_comparison

    df = pd.DataFrame({"quantity": ["tangential_restitution", "rebound_spin", "rebound_angle"],
                       "incidence_angle_deg": [20.0, 20.0, 20.0], "value": [0.6, 570.0, 12.0],
                       "units": ["1", "rad s-1", "degree"]})
    df.to_csv(tmp_path / "kharaz.csv", index=False)
    ds = kharaz_comparison(tmp_path / "kharaz.csv", fit_friction=False, curve_incidence_deg=np.arange(1.0, 80.0, 3.0))
    check(plots.plot_kharaz(ds), tmp_path, "kharaz")


def test_size_dependence(tmp_path):
    # a sweep with a leading radius dimension (one contact per measured size), as the analyst's sweeps
    spec = {"speed": [0.5, 1.5, 3.0, 8.0], "incidence_deg": [0.0, 30.0]}
    radius = xr.DataArray([1.29e-6, 3.45e-6], dims="radius", attrs={"units": "m"})
    ds = xr.concat([sweeps.run_sweep(C.at_radius(float(r)), spec, case="2.1", capture_speed=False)
                    for r in radius.values], dim=radius, combine_attrs="override")
    dyn = xr.Dataset({"capture_velocity": ("radius", [1.4, 0.6]), "critical_velocity": ("radius", [1e-3, 5e-4])},
                     coords={"radius": radius})
    p = check(plots.plot_size_dependence(ds, dyn), tmp_path, "sizes")
    assert len(p.figure.axes[0].get_legend().get_texts()) == 2  # one curve per diameter
    assert "critical velocity" in p.caption and "alpha" not in p.caption.split("(b)")[1]
    assert "incidence_deg = 0" in p.caption  # taken at normal incidence


def _assert_tick_labels_apart(fig, ax, what):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    for axis, horizontal in ((ax.xaxis, True), (ax.yaxis, False)):
        lo, hi = sorted(axis.get_view_interval())
        ticks = [t for t in axis.get_major_ticks() + axis.get_minor_ticks()
                 if t.label1.get_visible() and t.label1.get_text() and lo <= t.get_loc() <= hi]
        boxes = sorted((t.label1.get_window_extent(renderer) for t in ticks), key=lambda b: b.x0 if horizontal else b.y0)
        assert len(boxes) >= 2, (what, [t.label1.get_text() for t in ticks])
        for a, b in zip(boxes, boxes[1:]):
            assert (a.x1 <= b.x0 + 0.5) if horizontal else (a.y1 <= b.y0 + 0.5), (what, horizontal)


@pytest.mark.parametrize("span", [(0.8, 3.0), (1.0, 60.0), (5e-7, 5.0), (1e-9, 1e4)])
def test_log_axis_labels_do_not_overlap(span):
    """A log axis over part of a decade to 13 decades, in the report's style and panel size: the
    drawn tick labels never overlap."""
    with matplotlib.rc_context(plots.STYLE):
        fig = Figure(figsize=(7.0, 2.6), layout="constrained")
        ax = fig.subplots(1, 2)[1]
        ax.plot(span, span)
        ax.set_xscale("log")
        ax.set_yscale("log")
        plots._plain_log_labels(ax.yaxis)
        plots._plain_log_labels(ax.xaxis)
        _assert_tick_labels_apart(fig, ax, span)


def test_size_dependence_over_seven_decades_keeps_its_labels_apart():
    """Panel (b) of the analyst's sweep figure with a capture velocity of a few m/s and a critical
    velocity of 1e-6 m/s (the fitted material of the pipeline's test data): its labels once ran
    together at 1, 2 and 5 of every decade."""
    radii = np.array([1.29e-6, 3.45e-6])
    speed = np.geomspace(1.0, 60.0, 6)
    sweep = xr.Dataset({"e_n": (("radius", "speed"), np.tile(np.linspace(0.3, 0.8, 6), (2, 1))),
                        "outcome": (("radius", "speed"), np.zeros((2, 6), int))},
                       coords={"radius": radii, "speed": speed})
    dyn = xr.Dataset({"capture_velocity": ("radius", [5.0, 1.4]), "critical_velocity": ("radius", [3e-5, 5e-7])},
                     coords={"radius": radii})
    p = plots.plot_size_dependence(sweep, dyn)
    with matplotlib.rc_context(plots.STYLE):
        _assert_tick_labels_apart(p.figure, p.figure.axes[1], "capture velocity panel")


def test_size_dependence_of_a_pair_without_adhesion_says_nothing_is_captured(tmp_path):
    """A non-adhesive pair (f0 = 0, e.g. alumina on glass) has capture velocity 0 and no critical
    velocity: panel (b) says so instead of failing on a log axis with nothing to draw (the
    pipeline's figures job once stopped there)."""
    radii = np.array([10e-6, 40e-6])
    speed = np.geomspace(0.2, 20.0, 5)
    sweep = xr.Dataset({"e_n": (("radius", "speed"), np.tile(np.linspace(0.99, 0.95, 5), (2, 1))),
                        "outcome": (("radius", "speed"), np.zeros((2, 5), int))},
                       coords={"radius": radii, "speed": speed})
    dyn = xr.Dataset({"capture_velocity": ("radius", [0.0, 0.0]), "critical_velocity": ("radius", [np.nan, np.nan])},
                     coords={"radius": radii})
    p = check(plots.plot_size_dependence(sweep, dyn), tmp_path, "no_capture")
    ax_v = p.figure.axes[1]
    assert ax_v.get_yscale() == "linear" and not ax_v.get_lines()
    assert any("no capture" in t.get_text() for t in ax_v.texts)
    assert "every impact rebounds" in p.caption


def test_every_log_axis_of_a_plot_gets_readable_labels():
    """Plot applies the report's log-axis labels to every log axis (the fit and posterior figures
    once showed '10^0 10^1' under a speed axis from 1 to 60 m/s)."""
    fig = Figure(figsize=(4, 3))
    ax = fig.add_subplot()
    ax.plot([1.0, 60.0], [0.1, 0.9])
    ax.set_xscale("log")
    plots.Plot(fig, "a caption that is long enough to pass the checks of this module")
    assert isinstance(ax.xaxis.get_major_formatter(), plots._LogLabels)
    assert not isinstance(ax.yaxis.get_major_formatter(), plots._LogLabels)  # linear axis untouched
