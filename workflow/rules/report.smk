# The PDF report (microimpact.report.pdf.build_report): it reads the result files below and runs
# no model. Keys name the parts: the analyst's material per pair (fit and what it drives; KEY__I for
# the pair params.pairs[I]), the paper's
# reproduction, and the checks.


rule report:
    input:
        unpack(benchmark_outputs),
        unpack(stress_outputs),
        unpack(lammps_outputs),
        unpack(analyst_report_inputs),
        unpack(design_report_inputs),
        data_table=rules.validate_data.output.table,
        phase_portraits=rules.paper_dynamics.output.phase_portraits,
        dynamics=rules.paper_dynamics.output.dynamics,
        bifurcation=rules.paper_dynamics.output.bifurcation,
        reproduction=rules.reproduction.output.table,
        paper_sweeps=expand("results/paper/sweeps/case_{case}.nc", case=SWEEP_CASES),
        kharaz=rules.kharaz.output[0],
    output:
        report(
            "reports/report.pdf",
            caption="../report/report_pdf.rst",
            category="Report",
        ),
    log:
        "logs/report.log",
    benchmark:
        "benchmarks/report.tsv"
    conda:
        "../envs/microimpact.yaml"
    # one thread: the report is the last job, and the HTML figures run beside it (two workers
    # drew its figures 1 s faster but held the second core for all of its 6 s)
    threads: 1
    params:
        config=config,
        pairs=PAIRS,
    script:
        "../scripts/report.py"
