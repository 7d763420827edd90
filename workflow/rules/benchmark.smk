# Numerical checks of the engine: the work-precision study against the scipy reference solvers and
# the paper's fixed-step Runge-Kutta-Gill method (switchable: config benchmark.enabled; quick by
# default), and the seeded random stress sweep over decades of every input (config stress).


rule work_precision:
    output:
        netcdf="results/benchmark/benchmark.nc",
        json="results/benchmark/benchmark.json",
        markdown=report(
            "results/benchmark/benchmark.md",
            caption="../report/benchmark_table.rst",
            category="Tables",
        ),
        pdf="results/benchmark/work_precision.pdf",
        png=report(
            "results/benchmark/work_precision.png",
            caption="../report/work_precision.rst",
            category="C. Checks",
        ),
    log:
        "logs/work_precision.log",
    benchmark:
        "benchmarks/work_precision.tsv"
    priority: 5  # the longest job off that path
    conda:
        "../envs/microimpact.yaml"
    # the full study times the batch engine on both cores; the quick one (a check of the
    # numbers, beside other jobs) leaves the second core to them
    threads: 1 if config["benchmark"]["quick"] else 2
    params:
        quick=config["benchmark"]["quick"],
        throughput=config["benchmark"]["throughput"],
        out_dir=lambda wildcards, output: os.path.dirname(output.netcdf),
    script:
        "../scripts/work_precision.py"


rule stress:
    output:
        summary="results/stress_summary.json",
        netcdf="results/stress.nc",
    log:
        "logs/stress.log",
    benchmark:
        "benchmarks/stress.tsv"
    conda:
        "../envs/microimpact.yaml"
    threads: 1
    params:
        cases=config["stress"]["cases"],
        seed=config["stress"]["seed"],
        reference_every=config["stress"]["reference_every"],
        case_time_limit=config["stress"]["case_time_limit"],
    script:
        "../scripts/stress.py"
