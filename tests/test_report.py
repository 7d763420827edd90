"""The PDF report reads result files only: no solver is imported, the parts and their parameter sources show.

The result files are made here with the library (tests may run solvers; the report may not), small
enough to build in about a minute: a synthetic data set of two sizes fitted without confidence
intervals, two Table 2 cases on coarse grids for the analyst (per radius) and for the paper.
"""

import json
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402

from microimpact import presets  # noqa: E402
from microimpact.analysis.fitting import fit_damping  # noqa: E402
from microimpact.analysis.kharaz import kharaz_comparison  # noqa: E402
from microimpact.analysis.model_comparison import compare_normal_models  # noqa: E402
from microimpact.analysis.synthetic import make_synthetic_impacts  # noqa: E402
from microimpact.dynamics import nonlinear as dynamics  # noqa: E402
from microimpact.io import read_impacts  # noqa: E402
from microimpact.io.files import read_netcdf_groups, write_csv, write_netcdf  # noqa: E402
from microimpact.report.inputs import INPUT_KEYS  # noqa: E402
from microimpact.report.pdf import build_report  # noqa: E402
from microimpact.studies import sweeps  # noqa: E402
from microimpact.io.provenance import preset_parameter_source, source_of_fit, stamp_parameters  # noqa: E402
from microimpact.studies.material import material_dynamics, material_sweep  # noqa: E402
from microimpact.studies.sweeps import restitution_curves  # noqa: E402

FORBIDDEN = ("microimpact.solvers", "microimpact.dynamics", "microimpact.studies", "microimpact.analysis", "numba")
PAPER_SOURCE = preset_parameter_source("wall1990")
SPEEDS = [0.5, 1.5, 3.0, 8.0]


def test_report_imports_no_solver():
    code = ("import microimpact.report.pdf, microimpact.report.figures, sys; "
            f"print('\\n'.join(m for m in sys.modules if m.startswith({FORBIDDEN!r})))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert proc.stdout.strip() == "", f"the report imported: {proc.stdout.split()}"


def _case_spec(case, speeds):
    spec = sweeps.TABLE2_CASES[case]
    family = [k for k, v in spec.items() if k not in ("speed", "description") and isinstance(v, (list, dict))][0]
    values = np.asarray(sweeps.resolve_spec(spec)[family])
    return dict(spec, speed=list(speeds), **{family: [float(values[0]), float(values[-1])]})


def _analyst_files(tmp, fit_ds):
    """Per-radius dynamics and sweeps of the fitted material, as the pipeline writes them."""
    write_netcdf(material_dynamics(fit_ds), tmp / "analyst_dynamics.nc")
    files = []
    for case in ("2.1", "2.3"):
        write_netcdf(material_sweep(fit_ds, _case_spec(case, SPEEDS), case=case), tmp / f"analyst_{case}.nc")
        files.append(tmp / f"analyst_{case}.nc")
    return source_of_fit(fit_ds), files


def _paper_files(tmp):
    contact = presets.WALL_1990
    portraits = dynamics.phase_portraits(contact, [0.5, 1e-5], rtol=1e-8)
    for p in portraits:
        p.attrs.setdefault("parameter_source", PAPER_SOURCE)
    dynamics.save_phase_portraits(portraits, tmp / "portraits.nc")
    write_netcdf(stamp_parameters(dynamics.dynamics_summary(contact, [0.5, 1e-5]), contact, PAPER_SOURCE),
                 tmp / "dynamics.nc")
    write_netcdf(dynamics.bifurcation_plane(n_c1=31, n_c2=31), tmp / "bifurcation.nc")
    files = []
    for case in ("2.1", "2.3"):
        ds = sweeps.run_sweep(contact, _case_spec(case, SPEEDS), case=case)
        write_netcdf(stamp_parameters(ds, contact, PAPER_SOURCE), tmp / f"paper_{case}.nc")
        files.append(tmp / f"paper_{case}.nc")
    repro = pd.DataFrame({"id": ["vc"], "claim": ["critical velocity"], "source": ["Eq. (38)"],
                          "paper_value": ["1.45"], "toolkit_value": ["1.45"], "agree": [True], "note": [""]})
    write_csv(repro, tmp / "reproduction.csv")
    return files


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("results")
    gen = dict(radii=[1.29e-6, 3.45e-6], zeta_hertz=0.8, zeta_adhesion=20.0, n_per_radius=6, seed=3)
    make_synthetic_impacts(**gen).to_csv(tmp / "synthetic_impacts.csv", index=False)
    table = read_impacts(tmp / "synthetic_impacts.csv")
    write_csv(table, tmp / "table.csv")
    fit = fit_damping(table, presets.WALL_1990, confidence_intervals=False,
                      start_grid=([0.5, 1.0], [10.0, 30.0]))
    fit_ds = fit.to_dataset()
    write_netcdf(fit_ds, tmp / "fit.nc")
    write_netcdf(restitution_curves(fit_ds, {"start": 0.3, "stop": 30.0, "num": 12, "spacing": "log"}),
                 tmp / "fit_curves.nc")
    source, analyst_sweeps = _analyst_files(tmp, fit_ds)
    write_netcdf(compare_normal_models(table, presets.WALL_1990, ("ring", "jkr"), curve_points=12,
                                       start_grid=([0.5, 1.0], [10.0, 30.0])), tmp / "model_comparison.nc")
    kh = kharaz_comparison(fit_friction=False, curve_incidence_deg=np.arange(1.0, 80.0, 6.0))
    write_netcdf(kh, tmp / "kharaz.nc")
    stress = {"cases_run": 4, "cases_failed": 0, "seed": 1, "captures": 1, "failures_by_kind": {"energy": 0},
              "tolerances": {"energy": 1e-6}, "worst_energy_error": {"value": 1e-9, "case": {"case": 2}}}
    (tmp / "stress.json").write_text(json.dumps(stress))
    flags = pd.DataFrame({"row": table["row"], "e_n": table["e_n"], "capture_speed_ratio": 2.0,
                          "rotation_sensitive": 0, "angle_sensitive": 0, "near_capture": [1] + [0] * (len(table) - 1),
                          "parameter_source": source})
    write_csv(flags, tmp / "flags.csv")
    from microimpact.analysis.analyst_fit import AnalystFit
    from microimpact.analysis.posterior import capture_velocity_interval, restitution_bands, sample_posterior

    post = sample_posterior(table, fit, walkers=6, steps=10, seed=1, require_convergence=False)  # the form of the file, not its numbers
    AnalystFit(fit, posterior_dataset=post.to_dataset(restitution_bands(post, fit, n_draws=4),
                                                      capture_velocity_interval(post, fit, n_draws=3))).save(
        tmp / "fit_again.nc", tmp / "posterior.nc", tmp / "oblique.nc")
    lammps = pd.DataFrame({"speed": [0.1, 0.1, 2.0, 2.0], "incidence_deg": [0.0, 80.0, 0.0, 80.0],
                           "outcome_lammps": ["capture", "capture", "rebound", "rebound"],
                           "e_n_microimpact": [0.0, 0.0, 0.866025, 0.5], "e_n_lammps": [0.0, 0.0, 0.866024, 0.5],
                           "e_t_microimpact": [np.nan, np.nan, np.nan, 0.811674], "e_t_lammps": [np.nan, np.nan, np.nan, 0.811664],
                           "difference": [0.0, 0.0, 9.2e-8, 1e-7], "step_error": [0.0, 0.0, 2.8e-7, 3e-7],
                           "agrees": [True, True, True, False], "lammps_version": 20250722, "tolerance": 1e-3,
                           "parameter_source": "preset: wall1990, in LAMMPS's law"})
    write_csv(lammps, tmp / "lammps_check.csv")
    inputs = {"data_table": tmp / "table.csv", "lammps_check": tmp / "lammps_check.csv", "fit": tmp / "fit.nc", "fit_curves": tmp / "fit_curves.nc",
              "analyst_dynamics": tmp / "analyst_dynamics.nc", "analyst_sweeps": analyst_sweeps,
              "phase_portraits": tmp / "portraits.nc", "dynamics": tmp / "dynamics.nc",
              "bifurcation": tmp / "bifurcation.nc", "paper_sweeps": _paper_files(tmp),
              "reproduction": tmp / "reproduction.csv", "kharaz": tmp / "kharaz.nc", "stress": tmp / "stress.json",
              "flags": tmp / "flags.csv", "model_comparison": tmp / "model_comparison.nc",
              "posterior": tmp / "posterior.nc", "oblique": tmp / "oblique.nc"}
    return tmp, inputs, source


@pytest.fixture(scope="module")
def report_text(results):
    pypdf = pytest.importorskip("pypdf")
    tmp, inputs, _ = results
    path = build_report(tmp / "report.pdf", inputs, config={"data": "synthetic_impacts.csv", "stress": {}},
                        title="Microsphere test report")
    reader = pypdf.PdfReader(path)
    return [page.extract_text() or "" for page in reader.pages]


@pytest.mark.extended
def test_inputs_cover_every_key(results):
    _, inputs, _ = results
    # the design page (optional rule design) is tested with its own inputs in tests/test_design.py
    assert set(inputs) | {"work_precision", "design"} == set(INPUT_KEYS)


@pytest.mark.extended
def test_report_has_both_parts_and_their_sources(results, report_text):
    _, _, analyst_source = results
    text = "\n".join(report_text[1:]).replace("\n", " ")  # after the title page and its contents
    assert "Part A. The analyst's material" in text and "Part B. Reproduction of Cheng, Brach & Dunn" in text
    a, b = text.index("Part A."), text.index("Part B. Reproduction")
    assert a < text.index("Capture and critical velocity of the measured sizes") < b
    assert text.index("Sensitivity sweeps of the measured material") < b < text.index("Table 2 case 2.3 (Figs")
    # every section says which parameters made it: the fit's file and hash in part A, the preset in part B
    assert text[a:b].count(f"Parameters: {analyst_source}") >= 4  # fit, per-size dynamics, sweeps, flags
    assert "Normal contact models compared on the data" in text[a:b] and "Delta AIC" in text[a:b]
    assert "Measurement flags" in text[a:b] and "Of 12 impacts: 0 R, 0 A, 1 N" in text[a:b]  # the CLI letters
    assert text[b:].count(f"Parameters: {PAPER_SOURCE}") >= 3
    assert "Parameters: preset" not in text[a:b]
    assert "SYNTHETIC" in report_text[0] and "Contents" in report_text[0]
    assert "switched off" in text  # no benchmark given
    c = text.index("LAMMPS GRANULAR on the exported contact")
    assert c > text.index("Part C.") and "3 of 4 impacts agree within 0.001" in text[c:]
    assert "(2 captured by both)" in text[c:] and "run by LAMMPS 20250722" in text[c:]
    assert "e_t LAMMPS" in text[c:] and "0.811664" in text[c:]  # the tangential law's restitution is shown
    assert f"page {len(report_text)} of {len(report_text)}" in report_text[-1]


def test_unknown_or_missing_inputs_are_named(tmp_path):
    with pytest.raises(KeyError, match="sweeps"):
        build_report(tmp_path / "r.pdf", {"fit": "fit.nc", "sweeps": []})
    with pytest.raises(KeyError, match="fit"):
        build_report(tmp_path / "r.pdf", {"flags": "flags.csv"})


@pytest.mark.extended
def test_grouped_netcdf_reader(results):
    tmp, _, _ = results
    portraits = read_netcdf_groups(tmp / "portraits.nc")
    assert [p.attrs["normal_speed"] for p in portraits] == [0.5, 1e-5]


def test_figures_drawn_by_two_workers_are_the_images_drawn_by_one():
    """render_figures forks workers for speed; the images must not depend on it."""
    from matplotlib.figure import Figure

    from microimpact.report.layout import render_figures

    figures = []
    for k in range(3):
        fig = Figure(figsize=(3, 2))
        fig.add_subplot().plot([0, 1, 2], [0, k, 2 * k])
        figures.append(fig)
    serial = render_figures(figures, workers=1)
    parallel = render_figures(figures, workers=2)
    assert len(parallel) == 3
    for a, b in zip(serial, parallel):
        np.testing.assert_array_equal(a, b)


def _title_page(contents: int, title="Report"):
    from microimpact.report.layout import Layout

    lay = Layout(title)
    lay.contents = [(f"{k}. Section {k}", k) for k in range(1, contents + 1)]
    lay.title_page("subtitle", {"toolkit": "microimpact"}, footnote="Generated by a test. " * 8)
    return lay


@pytest.mark.parametrize("contents", [5, 40])
def test_title_page_contents_end_above_the_footnote(contents):
    """A long contents list is set closer instead of running into the footnote (it did with 15
    sections before the spacing adapted)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = _title_page(contents).pages[0].figure
    renderer = FigureCanvasAgg(fig).get_renderer()
    boxes = {t.get_text(): t.get_window_extent(renderer) for t in fig.texts}
    footnote = next(b for s, b in boxes.items() if s.startswith("Generated by"))
    last = boxes[f"{contents}. Section {contents}"]
    assert last.y0 > footnote.y1  # display coordinates: y grows upwards
    assert all(b.x1 <= fig.bbox.x1 for b in boxes.values())  # nothing runs off the page


def test_pdf_text_uses_core_fonts_unless_a_character_needs_embedding(tmp_path):
    """The report's text is set in the PDF core fonts (fast: nothing embedded); a title with a
    character outside their encoding keeps the embedded font, so the character is not lost."""
    pypdf = pytest.importorskip("pypdf")
    for title, core in (("Plain report, 5 um", True), ("Report on zeta \u03b6 \u2264 1", False)):
        lay = _title_page(3, title)
        path = tmp_path / f"{core}.pdf"
        lay.save(path, {"Title": title})
        page = pypdf.PdfReader(path).pages[0]
        font = page["/Resources"]["/Font"]
        fonts = {font[name]["/BaseFont"] for name in font}  # indexing resolves indirect objects (pypdf 4)
        assert any(name in ("/Helvetica", "/Helvetica-Bold") for name in fonts) == core, fonts
        assert title.split()[-1] in page.extract_text()


def test_a_table_never_splits_a_word_or_a_number_across_lines():
    """The 'Data by sphere size' table once set its header 'impacts' as 'impact' / 's'; columns now
    widen to their longest word or number (and the table is set smaller if it must be)."""
    from microimpact.report.layout import Layout

    lay = Layout("Report")
    lay.new_page("Tables")
    df = pd.DataFrame({"d": ["2.58", "6.9"], "n": [20, 20], "v": [-1.2345678e-05, 60.0]})
    lay.table(df, {"d": 4, "n": 6, "v": 5}, headers={"d": "diameter [um]", "n": "impacts", "v": "max v_n [m/s]"})
    text = "\n".join(t.get_text() for t in lay.pages[-1].figure.texts)
    lines = text.splitlines()
    for word in ("diameter", "impacts", "max", "[m/s]", "2.58", "-1.235e-05"):
        assert any(word in line.split() for line in lines), (word, lines)
