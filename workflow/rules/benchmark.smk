# Work-precision study of the fast engine against the scipy reference solver (switchable:
# config benchmark.enabled; quick mode by default).


rule work_precision:
    output:
        "results/work_precision.nc",
    params:
        quick=config["benchmark"].get("quick", True),
    log:
        "logs/work_precision.log",
    benchmark:
        "benchmarks/work_precision.tsv"
    threads: 1
    script:
        "../scripts/work_precision.py"
