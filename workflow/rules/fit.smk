# The analyst's material: the fit of the damping coefficients to the measured e_n(v_n) (the
# paper's Fig. 3 procedure), and everything the fitted parameters drive: the model curves, the
# measurement flags, the critical and capture velocity per measured size and the Table 2 sweeps
# of the fitted material over the measured sizes and speeds.


rule fit:
    input:
        data=config["data"],
        validated=rules.validate_data.output.table,
        materials=materials_path(),
    output:
        "results/analyst/fit.nc",
    params:
        material_pair=config["material_pair"],
        options=config["fit"],
        rtol=RTOL,
    log:
        "logs/fit.log",
    benchmark:
        "benchmarks/fit.tsv"
    conda:
        "../envs/microimpact.yaml"
    script:
        "../scripts/fit.py"


rule fit_curves:
    input:
        fit=rules.fit.output[0],
    output:
        "results/analyst/fit_curves.nc",
    params:
        rtol=RTOL,
    log:
        "logs/fit_curves.log",
    benchmark:
        "benchmarks/fit_curves.tsv"
    conda:
        "../envs/microimpact.yaml"
    script:
        "../scripts/fit_curves.py"


rule flags:
    input:
        data=config["data"],
        validated=rules.validate_data.output.table,
        materials=materials_path(),
        fit=rules.fit.output[0],
    output:
        csv="results/analyst/flags.csv",
        nc="results/analyst/flags.nc",
    params:
        rtol=RTOL,
    log:
        "logs/flags.log",
    benchmark:
        "benchmarks/flags.tsv"
    conda:
        "../envs/microimpact.yaml"
    script:
        "../scripts/flags.py"


rule material_dynamics:
    input:
        fit=rules.fit.output[0],
    output:
        "results/analyst/dynamics.nc",
    params:
        rtol=RTOL,
    log:
        "logs/material_dynamics.log",
    benchmark:
        "benchmarks/material_dynamics.tsv"
    conda:
        "../envs/microimpact.yaml"
    script:
        "../scripts/material_dynamics.py"


rule material_sweep:
    input:
        fit=rules.fit.output[0],
    output:
        "results/analyst/sweeps/case_{case}.nc",
    params:
        overrides=sweep_overrides,
        rtol=RTOL,
    log:
        "logs/analyst_sweeps/case_{case}.log",
    benchmark:
        "benchmarks/analyst_sweeps/case_{case}.tsv"
    conda:
        "../envs/microimpact.yaml"
    script:
        "../scripts/material_sweep.py"
