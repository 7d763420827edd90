# The PDF report: every result above, laid out by microimpact.report.pdf.build_report.


rule report:
    input:
        unpack(benchmark_outputs),
        unpack(stress_outputs),
        data_table=rules.validate_data.output.table,
        fit=rules.fit.output[0],
        phase_portraits=rules.phase_portraits.output[0],
        dynamics=rules.dynamics_summary.output[0],
        bifurcation=rules.bifurcation.output[0],
        reproduction=rules.reproduction.output.table,
        sweeps=[sweep_file(case) for case in SWEEP_CASES],
        flags=rules.flags.output.csv,
        kharaz=rules.kharaz.output[0],
    output:
        "reports/report.pdf",
    params:
        config=config,
    log:
        "logs/report.log",
    benchmark:
        "benchmarks/report.tsv"
    conda:
        "../envs/microimpact.yaml"
    script:
        "../scripts/report.py"
