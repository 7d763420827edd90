# The reproduction of the paper, from the paper's parameters (config paper_contact; Table 1 row 2
# by default): in one job (each part takes a second; one job saves two start-ups) the Fig. 5
# phase portraits, the numbers of the nonlinear analysis and the Fig. 4 bifurcation plane; and
# the reproduction table of the paper's claims.


rule paper_dynamics:
    output:
        phase_portraits="results/paper/phase_portraits.nc",
        dynamics="results/paper/dynamics.nc",
        bifurcation="results/paper/bifurcation.nc",
    log:
        "logs/paper_dynamics.log",
    benchmark:
        "benchmarks/paper_dynamics.tsv"
    conda:
        "../envs/microimpact.yaml"
    threads: 1
    params:
        contact=config["paper_contact"],
        speeds=config["phase_portrait_speeds"],
    script:
        "../scripts/paper_dynamics.py"


rule reproduction:
    output:
        table=report(
            "results/paper/reproduction.csv",
            caption="../report/reproduction.rst",
            category="Tables",
        ),
        markdown="results/paper/reproduction.md",
    log:
        "logs/reproduction.log",
    benchmark:
        "benchmarks/reproduction.tsv"
    conda:
        "../envs/microimpact.yaml"
    threads: 1
    params:
        contact=config["paper_contact"],
    script:
        "../scripts/reproduction.py"
