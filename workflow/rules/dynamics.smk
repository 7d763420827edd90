# The reproduction of the paper, from the paper's parameters (config paper_contact; Table 1 row 2
# by default): Fig. 5 phase portraits, the numbers of the nonlinear analysis, the Fig. 4
# bifurcation plane and the reproduction table of the paper's claims.


rule phase_portraits:
    output:
        "results/paper/phase_portraits.nc",
    params:
        contact=config["paper_contact"],
        speeds=config["phase_portrait_speeds"],
    log:
        "logs/phase_portraits.log",
    benchmark:
        "benchmarks/phase_portraits.tsv"
    conda:
        "../envs/microimpact.yaml"
    script:
        "../scripts/phase_portraits.py"


rule dynamics_summary:
    output:
        "results/paper/dynamics.nc",
    params:
        contact=config["paper_contact"],
        speeds=config["phase_portrait_speeds"],
    log:
        "logs/dynamics_summary.log",
    benchmark:
        "benchmarks/dynamics_summary.tsv"
    conda:
        "../envs/microimpact.yaml"
    script:
        "../scripts/dynamics_summary.py"


rule bifurcation:
    output:
        "results/paper/bifurcation.nc",
    params:
        contact=config["paper_contact"],
        speeds=config["phase_portrait_speeds"],
    log:
        "logs/bifurcation.log",
    benchmark:
        "benchmarks/bifurcation.tsv"
    conda:
        "../envs/microimpact.yaml"
    script:
        "../scripts/bifurcation.py"


rule reproduction:
    output:
        table="results/paper/reproduction.csv",
        markdown="results/paper/reproduction.md",
    params:
        contact=config["paper_contact"],
    log:
        "logs/reproduction.log",
    benchmark:
        "benchmarks/reproduction.tsv"
    conda:
        "../envs/microimpact.yaml"
    script:
        "../scripts/reproduction.py"
