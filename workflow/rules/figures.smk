# The figures of the HTML report (snakemake --report report.html): the standard figure of each
# result file, as `microimpact plot` draws it (microimpact.report.standard), with a caption from
# workflow/report/. The PDF report (report.smk) lays out the same figure functions on A4 pages.


rule fit_figure:
    input:
        result=rules.fit.output[0],
        curves=rules.material_simulations.output.fit_curves,
    output:
        report(
            "reports/figures/analyst/fit.png",
            caption="../report/fit.rst",
            category="A. The analyst's material",
        ),
    log:
        "logs/figures/analyst/fit.log",
    conda:
        "../envs/microimpact.yaml"
    threads: 1
    script:
        "../scripts/figure.py"


rule figure:
    input:
        result="results/{result}.nc",
    output:
        report(
            "reports/figures/{result}.png",
            caption="../report/figure.rst",
            category="Figures",
            subcategory="{result}",
        ),
    log:
        "logs/figures/{result}.log",
    wildcard_constraints:
        result=FIGURE_RESULT_PATTERN,
    conda:
        "../envs/microimpact.yaml"
    threads: 1
    script:
        "../scripts/figure.py"


rule sweep_figure:
    input:
        result="results/{part}/sweeps/case_{case}.nc",
    output:
        report(
            "reports/figures/{part}/sweeps/case_{case}.{variant}.png",
            caption="../report/sweep_figure.rst",
            category="Figures",
            subcategory="{part}/sweeps/case_{case}",
        ),
    log:
        "logs/figures/{part}/sweeps/case_{case}.{variant}.log",
    wildcard_constraints:
        part="analyst|paper",
        variant="restitution|energy_loss",
    conda:
        "../envs/microimpact.yaml"
    threads: 1
    params:
        variant="{variant}",
    script:
        "../scripts/figure.py"
