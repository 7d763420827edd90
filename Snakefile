# microimpact report pipeline (grows with the workflow issue).
rule all:
    input:
        "results/impact_example.json",

rule example_impact:
    output:
        "results/impact_example.json",
    shell:
        "microimpact simulate --preset wall1990 --speed 2.0 --incidence-deg 10 --json > {output}"
