# The analyst's material, once per material pair of the data ({pair}: PAIRS in common.smk): the
# fit of the damping coefficients to the measured e_n(v_n) (the paper's Fig. 3 procedure), the
# friction from the oblique columns (when the data have them), the posterior of the fitted
# parameters with its bands (config key posterior), and everything the fitted parameters drive: the
# measurement flags, and in one job (each is seconds; one job saves the start-up of six) the model
# curves, the critical and capture velocity per measured size and the Table 2 sweeps of the fitted
# material over the measured sizes and speeds.


rule fit:
    input:
        data=config["data"],
        validated=rules.validate_data.output.table,
        materials=materials_path(),
    output:
        "results/analyst/{pair}/fit.nc",
        posterior="results/analyst/{pair}/posterior.nc",
        oblique="results/analyst/{pair}/oblique.nc",
    log:
        "logs/fit/{pair}.log",
    benchmark:
        "benchmarks/fit/{pair}.tsv"
    priority: 10  # on the path to the report (data, fit, what uses the fit): started first
    conda:
        "../envs/microimpact.yaml"
    threads: 1
    params:
        material_pair=config["material_pair"],
        options=config["fit"],
        posterior=config["posterior"],
        rtol=RTOL,
    script:
        "../scripts/fit.py"


rule flags:
    input:
        data=config["data"],
        validated=rules.validate_data.output.table,
        materials=materials_path(),
        fit=rules.fit.output[0],
        posterior=rules.fit.output.posterior,
    output:
        csv=report(
            "results/analyst/{pair}/flags.csv",
            caption="../report/flags_table.rst",
            category="Tables",
        ),
        nc="results/analyst/{pair}/flags.nc",
    log:
        "logs/flags/{pair}.log",
    benchmark:
        "benchmarks/flags/{pair}.tsv"
    priority: 10  # on the path to the report (data, fit, what uses the fit): started first
    conda:
        "../envs/microimpact.yaml"
    threads: 1
    params:
        material_pair=config["material_pair"],
        n_draws=config["posterior"]["n_draws"],
        rtol=RTOL,
    script:
        "../scripts/flags.py"


rule material_simulations:
    input:
        fit=rules.fit.output[0],
    output:
        fit_curves="results/analyst/{pair}/fit_curves.nc",
        dynamics="results/analyst/{pair}/dynamics.nc",
        sweeps=expand(
            "results/analyst/{{pair}}/sweeps/case_{case}.nc", case=SWEEP_CASES
        ),
    log:
        "logs/material_simulations/{pair}.log",
    benchmark:
        "benchmarks/material_simulations/{pair}.tsv"
    priority: 10  # on the path to the report (data, fit, what uses the fit): started first
    conda:
        "../envs/microimpact.yaml"
    threads: 1
    params:
        cases=SWEEP_CASES,
        overrides=config["sweeps"],
        rtol=RTOL,
    script:
        "../scripts/material_simulations.py"
