# Optional: what to measure next for the analyst's material (microimpact.analysis.design): the
# impacts that most narrow the named parameters given the damping fit, as a JSON for the report's
# page and a measured-impact CSV template. Off unless config design: {enabled: true}.

DESIGN = {"enabled": False, "n": 20, "parameters": ["zeta_hertz"], "n_friction": 6, **config.get("design", {})}
DESIGN_ENABLED = as_bool(DESIGN["enabled"])


def design_report_inputs(wildcards):
    """The design of every material pair for the report (KEY__I as analyst_report_inputs); none when off."""
    if not DESIGN_ENABLED:
        return {}
    return {f"design__{i}": f"results/analyst/{p}/design.json" for i, p in enumerate(PAIRS)}


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
        n=int(DESIGN["n"]),
        parameters=list(DESIGN["parameters"]),
        n_friction=int(DESIGN["n_friction"]),
        rtol=RTOL,
    script:
        "../scripts/design.py"
