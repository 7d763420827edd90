# The PDF report (microimpact.report.pdf.build_report): it reads the result files below and runs
# no model. Keys name the parts: the analyst's material (fit and what it drives), the paper's
# reproduction, and the checks.


rule report:
    input:
        unpack(benchmark_outputs),
        unpack(stress_outputs),
        data_table=rules.validate_data.output.table,
        fit=rules.fit.output[0],
        posterior=rules.fit.output.posterior,
        oblique=rules.fit.output.oblique,
        fit_curves=rules.material_simulations.output.fit_curves,
        model_comparison=rules.model_comparison.output[0],
        flags=rules.flags.output.csv,
        analyst_dynamics=rules.material_simulations.output.dynamics,
        analyst_sweeps=rules.material_simulations.output.sweeps,
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
    script:
        "../scripts/report.py"
