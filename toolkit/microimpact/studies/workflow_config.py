"""The report pipeline's configuration: its start-up checks, as plain functions.

The Snakefile validates ``workflow/config/config.yaml`` against its JSON schema; what a schema cannot
say (a file exists, a material pair is in the materials config, a preset exists, a number has the
CLI's bounds) is checked here, before any job runs. :func:`config_problem` returns the first problem
as one line naming the config key and what is accepted, or None; the workflow raises it as a
``WorkflowError``. Keeping the checks in the library lets them be tested without starting Snakemake
and keeps the workflow's rule files thin.
"""

from __future__ import annotations

import os
from pathlib import Path

from microimpact import analysis
from microimpact.analysis.sampling_defaults import DEFAULT_MAX_STEPS, DEFAULT_WALKERS, MAX_SEED
from microimpact.io.materials import MaterialsError, default_materials_path, read_materials
from microimpact.presets import PRESETS, named_contact
from microimpact.solvers import check_time_budget
from microimpact.solvers.impact import check_rtol

__all__ = ["config_problem"]

#: the data files of the config: key -> what the file is (named in the one-line problem)
_FILES = (
    ("data", "impact CSV (data/README.md, 'Measured-impact CSV format')"),
    ("kharaz_data", "Kharaz et al. (2001) CSV"),
)
#: the most parameters a posterior chain of the pipeline can have: zeta_H, zeta_A, w_A, f
_MAX_CHAIN_PARAMETERS = 4


def _file_problem(config: dict, key: str, what: str, basedir: str) -> str | None:
    """None if ``config[key]`` is a readable file, else the one-line reason."""
    path = config[key]
    p = Path(path)
    how = f"--config {key}=path/to/file"
    if not p.exists():
        return (f"config key '{key}': {what} {path!r} does not exist (relative paths are taken from "
                f"{os.getcwd()}, else from {basedir}); give an existing file, e.g. {how}")
    if not p.is_file():
        return f"config key '{key}': {what} {path!r} is not a file (a directory?); give a file, e.g. {how}"
    if not os.access(p, os.R_OK):
        return f"config key '{key}': {what} {path!r} cannot be read (permissions); make it readable or give another file"
    return None


def _materials_problem(config: dict, basedir: str) -> str | None:
    if config["materials"] != "default":
        problem = _file_problem(config, "materials", "materials config (data/README.md, 'Materials config')",
                                basedir)
        if problem:
            return problem
        path = config["materials"]
    else:
        path = default_materials_path()
    try:
        pairs = read_materials(path)
    except MaterialsError as e:
        return f"config key 'materials': {path} is not a valid materials config: " + "; ".join(e.problems)
    if config["material_pair"] not in pairs:
        return (f"config key 'material_pair': {config['material_pair']!r} is not a pair of the materials "
                f"config {path}; accepted: {', '.join(sorted(pairs))}")
    return None


def _paper_contact_problem(spec) -> str | None:
    accepted = f"a preset name ({', '.join(sorted(PRESETS))}) or a mapping of microimpact.Contact fields in SI units"
    if isinstance(spec, str) and spec.lower() not in PRESETS:
        return f"config key 'paper_contact': {spec!r} is not a preset; accepted: {accepted}"
    try:
        named_contact(spec)
    except (ValueError, TypeError) as e:
        return f"config key 'paper_contact': {e}; accepted: {accepted}"
    return None


def _posterior_problem(post: dict) -> str | None:
    """The CLI's bounds for the sampler: a seed the posterior file can store (int32) and a chain
    that fits in memory, checked before the fit job starts rather than when it runs out."""
    if not post.get("enabled", True):
        return None
    seed = post.get("seed")
    if seed is not None and int(seed) > MAX_SEED:
        return (f"config key 'posterior': seed {seed} is above {MAX_SEED} (the posterior file stores it as "
                "a 32-bit integer)")
    if post.get("walkers") is None and post.get("max_steps") is None:
        # the library's defaults: a chain of 26 MB (posterior_memory), which any machine that runs the pipeline
        # holds; the check would import the sampler (scipy, xarray: 2 CPU-s) into snakemake's
        # start-up, which every run waits for before its first job
        return None
    try:
        analysis.posterior.check_posterior_memory(int(post.get("walkers") or DEFAULT_WALKERS),
                                                  int(post.get("max_steps") or DEFAULT_MAX_STEPS),
                                                  _MAX_CHAIN_PARAMETERS)
    except ValueError as e:
        return f"config key 'posterior': {e}"
    return None


def config_problem(config: dict, basedir: str = ".") -> str | None:
    """The first value of a schema-valid pipeline config that cannot work, as one line.

    Checks, in this order: the data files exist and are readable files; ``rtol`` has the CLI's
    bounds; the materials config reads and holds ``material_pair``; ``paper_contact`` is a preset or
    a valid :class:`microimpact.Contact`; the fit's ``time_budget`` is a positive finite number (the
    schema lets NaN through); the posterior's seed and chain size have the CLI's bounds.

    Parameters
    ----------
    config : dict
        The configuration after the schema's validation, with relative paths already resolved
        (the workflow resolves them from the working directory, else from the Snakefile's).
    basedir : str
        The Snakefile's directory, named in the message about a missing file.

    Returns
    -------
    str or None
        The problem, naming the config key, the value and what is accepted; None when every
        value can work.

    Examples
    --------
    >>> config_problem({"data": "no/such.csv"}).split(":")[0]
    "config key 'data'"
    """
    for key, what in _FILES:
        problem = _file_problem(config, key, what, basedir)
        if problem:
            return problem
    try:  # the bounds of the CLI's --rtol, from the one check both use
        check_rtol(config["rtol"])
    except (TypeError, ValueError) as e:
        return f"config key 'rtol': {e}"
    problem = _materials_problem(config, basedir) or _paper_contact_problem(config["paper_contact"])
    if problem:
        return problem
    try:
        check_time_budget(config["fit"].get("time_budget"), "time_budget")
    except ValueError as e:
        return f"config key 'fit': {e}"
    return _posterior_problem(config.get("posterior") or {})
