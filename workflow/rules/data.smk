# Measured data: validate the impact CSV (every problem reported at once, with row and column)
# and keep a copy of the validated table in SI units for the report.


rule validate_data:
    input:
        data=config["data"],
        materials=materials_path(),
    output:
        table="results/impacts_validated.csv",
    log:
        "logs/validate_data.log",
    benchmark:
        "benchmarks/validate_data.tsv"
    priority: 10  # on the path to the report (data, fit, what uses the fit): started first
    conda:
        "../envs/microimpact.yaml"
    params:
        material_pair=config["material_pair"],
    script:
        "../scripts/validate_data.py"
