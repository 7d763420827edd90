# Contact models beyond the paper: the normal models (the paper's adhesion ring force, JKR, DMT) and the
# Thornton & Ning (1998) elastic-plastic adhesive law
# fitted to the same e_n(v_n) data, with AIC and BIC side by side
# (microimpact.analysis.model_comparison.compare_normal_models).


rule model_comparison:
    input:
        data=config["data"],
        validated=rules.validate_data.output.table,
        materials=materials_path(),
    output:
        "results/analyst/{pair}/model_comparison.nc",
    log:
        "logs/model_comparison/{pair}.log",
    benchmark:
        "benchmarks/model_comparison/{pair}.tsv"
    conda:
        "../envs/microimpact.yaml"
    threads: 1
    params:
        material_pair=config["material_pair"],
        models=["ring", "jkr", "dmt", "thornton_ning"],
        rtol=RTOL,
    script:
        "../scripts/model_comparison.py"
