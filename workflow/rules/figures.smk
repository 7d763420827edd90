# The figures of the HTML report (snakemake --report report.html): the standard figure of each
# result file, as `microimpact plot` draws it (microimpact.report.standard), with its caption from
# workflow/report/figure.rst. One job per part (FIGURE_PARTS) draws all of that part's figures: a
# job per figure cost a process start and the imports (1.5-2 s) for 0.3 s of drawing. The PDF
# report (report.smk) lays out the same figure functions on A4 pages.


rule figures:
    input:
        unpack(part_figure_inputs),
    output:
        report(
            directory("reports/figures/{part}"),
            patterns=FIGURE_PATTERNS,
            caption="../report/figure.rst",
            category="Figures",
            subcategory="{part}",
        ),
    log:
        "logs/figures/{part}.log",
    benchmark:
        "benchmarks/figures_{part}.tsv"
    wildcard_constraints:
        part="|".join(FIGURE_PARTS),
    conda:
        "../envs/microimpact.yaml"
    threads: 1  # drawn in turn: the other core runs the next job meanwhile
    params:
        figures=lambda wildcards: part_figures(wildcards.part),
    script:
        "../scripts/figures.py"
