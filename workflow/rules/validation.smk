# Validation of the tangential/rotational part of the model against real measured oblique
# impacts (Kharaz et al. 2001; data/README.md).


rule kharaz:
    input:
        config["kharaz_data"],
    output:
        "results/kharaz.nc",
    log:
        "logs/kharaz.log",
    benchmark:
        "benchmarks/kharaz.tsv"
    conda:
        "../envs/microimpact.yaml"
    threads: 1
    params:
        # sub-models of the "selected" model (config key contact_models; {} when absent)
        contact_models=config.get("contact_models", {}),
    script:
        "../scripts/kharaz.py"


# LAMMPS itself on the paper's microsphere exported as LAMMPS GRANULAR input (config key lammps).
rule lammps_check:
    output:
        contact="results/lammps/contact.lmp",
        table="results/lammps/check.csv",
    log:
        "logs/lammps_check.log",
    benchmark:
        "benchmarks/lammps_check.tsv"
    conda:
        "../envs/microimpact.yaml"
    threads: 1
    params:
        contact=config["paper_contact"],
    script:
        "../scripts/lammps_check.py"
