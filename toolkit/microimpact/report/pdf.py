"""The PDF report of the pipeline, assembled from result files only.

:func:`build_report` lays out ``reports/report.pdf`` from the NetCDF/CSV/JSON results of the
Snakemake workflow (keys in :data:`microimpact.report.inputs.INPUT_KEYS`) in three parts:

A. the analyst's material, with the parameters of the fit (one part per material pair of the data): the damping fit (Fig. 3 analogue),
   the normal contact models compared on the data (:mod:`.models`), capture and critical velocity
   per measured size, the Table 2 sweeps at the measured sizes, the measurement flags
   (:mod:`.analyst`) and what to measure next (:mod:`microimpact.report.design`);
B. the reproduction of the paper with the paper's parameters (Table 1 row 2): the nonlinear
   dynamics (Figs. 4, 5), the Table 2 sweeps (Figs. 7-14) and the table of the paper's claims
   (:mod:`.paper`);
C. checks: the Kharaz et al. (2001) validation, the work-precision benchmark, the stress sweep and
   the configuration (:mod:`.checks`).

Every section prints the ``parameter_source`` of the files it shows. The report imports no solver
and runs no model; figures come from :mod:`.figures`, the page layout from :mod:`.layout`.

Layout engine, decided: we keep the matplotlib page layout (:mod:`.layout`, under 300 lines), not a
document template or Snakemake's ``--report``. Snakemake's report is an HTML/zip archive made by a
separate ``snakemake --report`` call after the run, so it cannot be the ``reports/report.pdf`` target
of ``rule all``, and it lays out files rather than tables and captions computed from their contents.
A template (Jinja2 to LaTeX or to HTML with WeasyPrint) would move the layout into a second language
and add a TeX installation or a browser engine to the conda environment, for a document whose
content - figures with captions, tables, paragraphs - the matplotlib engine already sets in one
searchable PDF with no dependency beyond matplotlib. What made the old module long was the mixing
of layout, file reading and section content in 860 lines, which the split into layout, inputs and
the three parts removes.

Paper: Cheng, Brach & Dunn (2002), Aerosol Sci. Technol. 36:1081-1093, doi:10.1080/02786820290092221.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import pandas as pd

from microimpact import __version__
from microimpact.model.contact import PAPER_REFERENCE
from microimpact.report import analyst, checks, design, models, paper
from microimpact.io.impacts import select_material_pair
from microimpact.report.inputs import (ANALYST_KEYS, INPUT_KEYS, as_list, check_inputs, git_commit, is_synthetic, provenance,
                                       read_dataset, read_json, read_portraits, read_table, read_verdict)
from microimpact.report.layout import PAGE_SIZE, Layout

__all__ = ["build_report", "INPUT_KEYS", "PAGE_SIZE", "is_synthetic", "git_commit", "provenance"]

_DEFAULT_TITLE = "Microsphere contact/impact report"


def _optional(inputs: Mapping, key: str, reader):
    return reader(inputs[key]) if key in inputs else None


def _analyst_part(lay: Layout, inputs: Mapping, data: pd.DataFrame | None, synthetic: bool,
                  label: str = "A", pair: str | None = None) -> list[tuple[str, str]]:
    """Part A (A1, A2, ... with several material pairs): every result made with the parameters of the
    fit to the analyst's data of one material pair. Returns the part's verdict lines for the title page."""
    fit = read_dataset(inputs["fit"])
    verdict = read_verdict(fit)
    pair = pair or fit.attrs.get("fit_material_pair")
    lay.part(
        f"Part {label}. The analyst's material" + (f": {pair}" if pair else "") + " (parameters from the fit)",
        f"Results for the data of {fit.attrs.get('fit_source', 'the analyst')}"
        + (f", the rows of material pair {pair}" if pair else "")
        + (" (SYNTHETIC)" if synthetic else "") + ". The damping coefficients zeta_H, zeta_A (and w_A when it is "
        "fitted) come from the damping fit (its verdict first, then the fit itself); every simulation in this part uses them, at the measured sphere "
        "sizes and over the measured speed range.")
    analyst.summary_section(lay, fit, verdict)
    analyst.fit_section(lay, fit, _optional(inputs, "fit_curves", read_dataset), data, synthetic)
    obl = _optional(inputs, "oblique", read_dataset)
    if obl is not None and "friction" not in obl:  # no oblique columns: one line under the fit
        analyst.oblique_section(lay, obl)
    post = _optional(inputs, "posterior", read_dataset)
    if post is not None:
        analyst.posterior_section(lay, fit, post, verdict.rejected_note("the posterior, its bands and capture velocities"))
    if obl is not None and "friction" in obl:
        analyst.oblique_section(lay, obl, verdict.rejected_note("the friction fit (made at the fitted damping)"))
    if "model_comparison" in inputs:
        models.model_comparison_section(lay, read_dataset(inputs["model_comparison"]), synthetic)
    dyn = _optional(inputs, "analyst_dynamics", read_dataset)
    if dyn is not None:
        analyst.analyst_dynamics_section(lay, dyn, verdict.rejected_note("the capture and critical velocities"))
    sweeps = [read_dataset(s) for s in as_list(inputs.get("analyst_sweeps"))]
    if sweeps:
        analyst.analyst_sweeps_section(lay, sweeps, dyn, verdict.rejected_note("the sweeps"))
    if "flags" in inputs:
        flags_path = inputs["flags"] if isinstance(inputs["flags"], (str, os.PathLike)) else None
        analyst.flags_section(lay, read_table(inputs["flags"]), data, fit=fit, verdict=verdict, path=flags_path)
    if "design" in inputs:
        design.design_section(lay, read_json(inputs["design"]))
    return analyst.verdict_title_lines(verdict, f"Part {label}" + (f" ({pair})" if pair else ""))


def _rows_of_pair(data: pd.DataFrame | None, pair: str, default: str | None) -> pd.DataFrame | None:
    """The validated table's rows of one material pair (None when there are none)."""
    if data is None:
        return None
    try:
        return select_material_pair(data, pair, default=default)
    except ValueError:
        return None


def _paper_part(lay: Layout, inputs: Mapping) -> None:
    """Part B: the paper's figures and numbers, made with the paper's parameters."""
    keys = ("phase_portraits", "dynamics", "bifurcation", "reproduction", "paper_sweeps")
    if not any(k in inputs for k in keys):
        return
    lay.part(
        "Part B. Reproduction of Cheng, Brach & Dunn (2002) with the paper's parameters",
        f"The analogues of the figures and numbers of {PAPER_REFERENCE}, computed with the paper's parameter set "
        "(Table 1 row 2, or the configured contact where a section says 'config'). Nothing in this part depends "
        "on the analyst's data.")
    bif, dyn = _optional(inputs, "bifurcation", read_dataset), _optional(inputs, "dynamics", read_dataset)
    if bif is not None or dyn is not None:
        paper.dynamics_section(lay, bif, dyn)
    if "phase_portraits" in inputs:
        paper.portraits_section(lay, read_portraits(inputs["phase_portraits"]))
    sweeps = [read_dataset(s) for s in as_list(inputs.get("paper_sweeps"))]
    if sweeps:
        paper.paper_sweeps_section(lay, sweeps)
    if "reproduction" in inputs:
        repro = inputs["reproduction"]
        paper.reproduction_section(lay, read_table(repro), path=repro if isinstance(repro, (str, os.PathLike)) else None)


def _checks_part(lay: Layout, inputs: Mapping, config: Mapping) -> None:
    """Part C: validation against real data, the numerics, and the configuration."""
    lay.part("Part C. Checks of the model and the numerics",
             "Validation against published measurements, the accuracy and cost of the solvers, and a seeded "
             "stress sweep of the engine over wide parameter ranges.")
    if "kharaz" in inputs:
        checks.kharaz_section(lay, read_dataset(inputs["kharaz"]))
    checks.benchmark_section(lay, _optional(inputs, "work_precision", read_dataset))
    checks.stress_section(lay, _optional(inputs, "stress", read_json), config.get("stress"))
    if "lammps_check" in inputs:
        checks.lammps_section(lay, read_table(inputs["lammps_check"]))
    if config:
        checks.config_section(lay, config)


def build_report(path, inputs: Mapping, config: Mapping | None = None, title: str | None = None, *,
                 pairs: Mapping[str, Mapping] | None = None, workers: int = 1) -> Path:
    """Build the PDF report from the pipeline's result files.

    Parameters
    ----------
    path : str or os.PathLike
        PDF to write (atomically).
    inputs : mapping of str to path (or list of paths)
        Result files by key; ``fit`` is required, every other key may be missing (its section is
        left out or says why it is empty). Keys (see :data:`microimpact.report.inputs.INPUT_KEYS`):
        analyst part ``data_table`` (CSV), ``fit``, ``fit_curves``, ``posterior``, ``oblique``, ``flags`` (CSV),
        ``analyst_dynamics``, ``analyst_sweeps`` (list), ``model_comparison``, ``design`` (JSON); paper part ``phase_portraits``,
        ``dynamics``, ``bifurcation``, ``reproduction`` (CSV), ``paper_sweeps`` (list); checks
        ``kharaz``, ``work_precision``, ``stress`` (JSON). NetCDF unless stated. In-memory
        objects (Dataset, DataFrame, dict, list of Datasets) are accepted in place of files.
    pairs : mapping of str to mapping, optional
        The analyst's part per material pair: pair name -> its analyst inputs (the keys
        :data:`~microimpact.report.inputs.ANALYST_KEYS`, ``fit`` required). The report then has one
        Part A per pair (A1, A2, ... when there are several), each with the data table's rows of its
        pair (unlabelled rows belong to ``config["material_pair"]``), and ``inputs`` holds no
        analyst key.
    config : mapping, optional
        The pipeline configuration (title page and appendix).
    title : str, optional
        Report title; default ``config["report_title"]`` or a generic one.
    workers : int
        Processes that draw the figures (the pipeline passes its rule's threads). The PDF is the
        same for any number.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    KeyError
        For an unknown key or a missing ``fit``.

    Examples
    --------
    A report of a damping fit alone (the data table given in memory): the title page, the fit's
    section, and Part C with its empty benchmark and stress sections; without a fit it is refused:

    >>> from pypdf import PdfReader
    >>> from microimpact.analysis.fitting import fit_damping
    >>> from microimpact.analysis.synthetic import write_synthetic_impacts
    >>> from microimpact.io import default_materials_path, read_impacts, read_materials
    >>> material = read_materials(default_materials_path())["ammonium_fluorescein_on_silicon"]
    >>> table = read_impacts(write_synthetic_impacts("six.csv", radii=(3.45e-6,), n_per_radius=6, seed=3))
    >>> fit = fit_damping(table, material, confidence_intervals=False).to_dataset()
    >>> pdf = PdfReader(build_report("report.pdf", {"fit": fit, "data_table": table}))
    >>> len(pdf.pages), pdf.metadata.title
    (4, 'Microsphere contact/impact report')
    >>> "1. Verdict" in pdf.pages[1].extract_text(), "2. Damping fit (analogue of Fig. 3)" in pdf.pages[2].extract_text()
    (True, True)
    >>> build_report("report.pdf", {"data_table": table})
    Traceback (most recent call last):
    ...
    KeyError: "build_report: missing required input(s) ['fit'] (fit: damping fit NetCDF (DampingFit.to_dataset))"
    """
    if pairs is None:
        inputs = check_inputs(inputs)
    else:
        inputs = check_inputs(inputs, keys=[k for k in INPUT_KEYS if k not in ANALYST_KEYS], required=[])
        pairs = {p: check_inputs(v, keys=ANALYST_KEYS, required=["fit"]) for p, v in pairs.items()}
        if not pairs:
            raise KeyError("build_report: pairs= holds no material pair")
    config = dict(config or {})
    title = title or config.get("report_title") or _DEFAULT_TITLE
    data = _optional(inputs, "data_table", read_table)
    prov = provenance(config, version=__version__, data_table=data)
    synthetic = "SYNTHETIC" in prov.get("data", "")

    lay = Layout(title)
    if pairs is None:
        verdicts = _analyst_part(lay, inputs, data, synthetic)
    else:
        verdicts = [line for i, (pair, pair_inputs) in enumerate(pairs.items())
                    for line in _analyst_part(lay, pair_inputs, _rows_of_pair(data, pair, config.get("material_pair")),
                                              synthetic, label="A" if len(pairs) == 1 else f"A{i + 1}", pair=pair)]
    _paper_part(lay, inputs)
    _checks_part(lay, inputs, config)
    lay.title_page(
        f"Microsphere impact model of {PAPER_REFERENCE}: A. the analyst's material with the fitted parameters; "
        "B. the reproduction of the paper with its own parameters; C. validation and numerical checks.",
        prov, warning="DATA: SYNTHETIC (generated with known parameters; not a measurement)" if synthetic else None,
        footnote="Generated by the microimpact Snakemake pipeline (Snakefile, workflow/); every number and figure "
                 "is read from the files under results/ (the report runs no simulation). Units are SI unless "
                 "stated; angles in degrees.", verdicts=verdicts)
    path = Path(path)
    lay.save(path, {"Title": title, "Author": f"microimpact {__version__}",
                    "Subject": "Microsphere impact model of Cheng, Brach & Dunn (2002)",
                    "Keywords": "synthetic data" if synthetic else "measured data"}, workers=workers)
    return path
