"""Analysis: what is learned from measurements.

- :mod:`.fitting`: zeta_H, zeta_A (and optionally w_A) fitted to measured e_n(v_n) with lmfit.
- :mod:`.fit_result`: the one save/load protocol of every fit result (:class:`FitResult`), and the
  damping fit's result record (:class:`DampingFit`), its NetCDF form and its formatter; reading a
  fit needs no lmfit.
- :mod:`.design`: the next impacts to measure to narrow named parameters (Fisher information).
- :mod:`.flags`: which measurements unmeasured spin, angle error or closeness to capture make
  unreliable.
- :mod:`.kharaz`: the model against the Kharaz et al. (2001) oblique-impact measurements.
- :mod:`.synthetic`: labelled synthetic measurements from stated parameters.
- :mod:`.dem_fit`: the damping of LAMMPS GRANULAR's laws fitted to measured e_n, and the laws ranked.
- :mod:`.dem_friction`: the friction mu of LAMMPS GRANULAR's tangential laws fitted to oblique rebounds.
- :mod:`.plastic_fit`: the Thornton & Ning elastic-plastic adhesive law fitted to e_n(v_n) (yield
  velocity and w_A).
- :mod:`.model_comparison`: the normal laws fitted to the same e_n(v_n) and ranked by AIC.
- :mod:`.speed_curves`: certified Chebyshev curves of e_n in speed, so that many rows cost a few solves.
"""

from microimpact._lazy import lazy_exports as _lazy_exports

#: public name -> the module of microimpact.analysis that defines it (tests/test_packaging.py checks
#: that this table holds every module's ``__all__``)
_HOMES = {
    **dict.fromkeys(("AnalystFit", "analyse_impacts", "exclude_rows", "side_by_side", "POSTERIOR_DEFAULTS"), "analyst_fit"),
    **dict.fromkeys(("DesignSpace", "ExperimentDesign", "design_impacts", "fisher_widths", "uniform_design",
                     "restitution_sensitivities", "design_template", "DESIGN_CRITERIA", "SENSITIVITY_FLOOR",
                     "TEMPLATE_COLUMNS", "MAX_NEW_IMPACTS", "MAX_CANDIDATE_SPEEDS", "design_friction",
                     "tangential_sensitivities", "FRICTION_RANGE", "OBLIQUE_ANGLES_DEG", "uniform_oblique_design",
                     "design_record", "design_next_impacts", "fit_design_space"), "design"),
    **dict.fromkeys(("DEFAULT_NEW_IMPACTS", "DEFAULT_NEW_OBLIQUE", "DEFAULT_PARAMETERS", "OBLIQUE_QUANTITIES",
                     "DEFAULT_OBLIQUE_QUANTITY", "DEFAULT_E_T_SIGMA", "DEFAULT_REBOUND_ANGLE_SIGMA",
                     "DEFAULT_REBOUND_SPIN_SIGMA"), "design_defaults"),
    **dict.fromkeys(("split_rhat", "ess_bulk", "RHAT_MAX", "ESS_MIN"), "diagnostics"),
    **dict.fromkeys(("SpeedCurves", "HALF_DEGREE", "SAFETY", "TOLERANCE_FACTOR", "NEAR_CAPTURE", "MIN_ROWS",
                     "MAX_PIECES", "SETUP_MARGIN", "chebyshev_matrices", "certified_curve"), "speed_curves"),
    **dict.fromkeys(("FitResult", "DampingFit", "fit_parameter_table", "format_fit", "PARAMETER_NAMES", "SIGMA_LEVELS",
                     "PARAMETER_TABLE_COLUMNS"), "fit_result"),
    **dict.fromkeys(("FitProblem", "fit_damping", "damping_residual", "model_restitution", "DEFAULT_START_GRID",
                     "robust_terms", "loss_description", "FIT_METHODS", "EMULATOR_MIN_ROWS", "EMULATOR_MAX_SHIFT",
                     "emulator_shift_bound"),
                    "fitting"),
    **dict.fromkeys(("flag_measurements", "write_flags", "fibonacci_sphere", "flag_summary", "DEFAULT_THRESHOLDS",
                     "FLAG_LETTERS"), "flags"),
    **dict.fromkeys(("ParameterStatus", "STATUSES", "parameter_status", "profile_interval", "chi2_threshold",
                     "status_variables", "status_from_variables", "status_from_interval", "DEFAULT_LEVEL"),
                    "identifiability"),
    **dict.fromkeys(("kharaz_comparison", "kharaz_summary", "kharaz_table", "default_kharaz_path", "read_kharaz",
                     "KHARAZ_CONDITIONS", "UNLOADING_READINGS"), "kharaz"),
    **dict.fromkeys(("compare_normal_models", "normal_model_restitution", "comparison_verdict", "DEFAULT_MODELS"), "model_comparison"),
    **dict.fromkeys(("PlasticFit", "PlasticProblem", "fit_thornton_ning", "PLASTIC_PARAMETERS", "PLASTIC_RANGES",
                     "PLASTIC_UNITS", "PLASTIC_START_GRID", "STICKING_RAYS"), "plastic_fit"),
    **dict.fromkeys(("FrictionFit", "ObliqueProblem", "fit_friction", "oblique_model", "rebound_state",
                     "effective_sigma", "TANGENTIAL_PARAMETERS", "PARAMETER_BOUNDS", "OBSERVABLE_UNITS"), "oblique"),
    **dict.fromkeys(("fit_dem_friction", "rank_dem_tangential_laws", "dem_friction_coverage"), "dem_friction"),
    **dict.fromkeys(("Posterior", "PosteriorError", "sample_posterior", "prior_bounds", "posterior_contacts",
                     "restitution_bands", "capture_velocity_interval", "sweep_bands", "summary_table",
                     "PARAMETER_UNITS", "EIV_METHODS", "GAUSS_HERMITE_NODES", "CONDITIONAL_ON_REJECTED", "METHODS", "DEFAULT_METHOD",
                     "EMULATOR_TOLERANCE"), "posterior"),
    **dict.fromkeys(("DEFAULT_WALKERS", "DEFAULT_MAX_STEPS", "DEFAULT_SEED", "DEFAULT_N_DRAWS", "MAX_SEED", "LIKELIHOODS",
                     "DEFAULT_NU", "LOSSES", "DEFAULT_LOSS", "DEFAULT_FIT_METHOD"),
                    "sampling_defaults"),
    **dict.fromkeys(("spin_explanation", "SPIN_VARIABLES"), "spin"),
    **dict.fromkeys(("SYNTHETIC_DEFAULTS", "SYNTHETIC_OBLIQUE_DEFAULTS", "make_synthetic_impacts",
                     "make_synthetic_oblique", "write_synthetic_impacts"), "synthetic"),
    **dict.fromkeys(("DampingTarget", "damping_from_target"), "target"),
    **dict.fromkeys(("DEM_LAWS", "DemLawFit", "candidate_laws", "dem_law_contact", "dem_law_restitution", "fit_dem_law", "rank_dem_laws",
                     "ranked_by_aic", "information_criteria", "dem_fit_coverage", "INTERVAL_LEVEL", "REGION_RAYS"), "dem_fit"),
    **dict.fromkeys(("Verdict", "assess_residuals", "ADEQUATE", "INADEQUATE", "NO_UNCERTAINTIES", "ADEQUACY_P",
                     "OUTLIER_FALSE_ALARM", "MAX_OUTLIER_FRACTION", "sidak_threshold", "VERDICT_ATTRS",
                     "p_value_text"), "verdict"),
    **dict.fromkeys(("thornton_restitution", "make_outlier_impacts", "make_thornton_impacts",
                     "make_rebound_only_impacts", "DIRTY_MATERIAL_PAIR"), "dirty_data"),
}
#: the modules, importable as attributes
_MODULES = tuple(sorted(set(_HOMES.values())))

__all__ = list(_HOMES)


__getattr__, __dir__ = _lazy_exports("microimpact.analysis", _HOMES, _MODULES)
