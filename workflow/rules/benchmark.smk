# Work-precision study of the fast engine against the scipy reference solvers and the paper's
# fixed-step Runge-Kutta-Gill method (switchable: config benchmark.enabled; quick by default).


rule work_precision:
    output:
        netcdf="results/benchmark/benchmark.nc",
        json="results/benchmark/benchmark.json",
        markdown="results/benchmark/benchmark.md",
        pdf="results/benchmark/work_precision.pdf",
        png="results/benchmark/work_precision.png",
    params:
        quick=config["benchmark"]["quick"],
        throughput=config["benchmark"]["throughput"],
        out_dir=lambda wildcards, output: os.path.dirname(output.netcdf),
    log:
        "logs/work_precision.log",
    benchmark:
        "benchmarks/work_precision.tsv"
    conda:
        "../envs/microimpact.yaml"
    script:
        "../scripts/work_precision.py"
