# Fit of the damping coefficients to the measured e_n(v_n) (the paper's Fig. 3 procedure) and the
# measurement flags that compare each impact with the fitted model.


rule fit:
    input:
        data=config["data"],
        validated=rules.validate_data.output.table,
        materials=materials_path(),
    output:
        "results/fit.nc",
    params:
        material_pair=config["material_pair"],
        options=config["fit"],
    log:
        "logs/fit.log",
    benchmark:
        "benchmarks/fit.tsv"
    conda:
        "../envs/microimpact.yaml"
    script:
        "../scripts/fit.py"


rule flags:
    input:
        data=config["data"],
        validated=rules.validate_data.output.table,
        materials=materials_path(),
        fit=rules.fit.output[0],
    output:
        csv="results/flags.csv",
        nc="results/flags.nc",
    log:
        "logs/flags.log",
    benchmark:
        "benchmarks/flags.tsv"
    conda:
        "../envs/microimpact.yaml"
    script:
        "../scripts/flags.py"
