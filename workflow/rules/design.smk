# Optional: what to measure next for the analyst's material (microimpact.analysis.design): the
# impacts that most narrow the named parameters given the damping fit, as a JSON for the report's
# page and a measured-impact CSV template. Off unless config design: {enabled: true}.


rule design:
    input:
        fit=rules.fit.output[0],
    output:
        json="results/analyst/{pair}/design.json",
        csv="results/analyst/{pair}/design.csv",
    log:
        "logs/design/{pair}.log",
    benchmark:
        "benchmarks/design/{pair}.tsv"
    conda:
        "../envs/microimpact.yaml"
    threads: 1
    params:
        options=DESIGN_OPTIONS,
        rtol=RTOL,
    script:
        "../scripts/design.py"
