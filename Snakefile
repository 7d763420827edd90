# microimpact report pipeline: fit -> simulations -> sensitivity sweeps -> NetCDF -> PDF report.
#
#   snakemake --cores 2                                   # bundled (synthetic) data
#   snakemake --cores 2 --config data=path/to/impacts.csv # the same report for your data
#   snakemake --profile workflow/profiles/slurm           # on a SLURM cluster (docs/cluster.md)
#
# Every rule runs a thin script in workflow/scripts/ that calls one microimpact function; the
# configuration (workflow/config/config.yaml) is validated against its JSON schema first.
import os

from snakemake.utils import min_version, validate

min_version("8.17")


# the workflow's own files are found from the Snakefile's directory, so that it also runs as
# `snakemake -s path/to/Snakefile -d elsewhere` and from the installed package (`microimpact workflow`)
configfile: os.path.join(workflow.basedir, "workflow", "config", "config.yaml")


include: "workflow/rules/typed_config.smk"


validate(config, "workflow/schemas/config.schema.yaml")


# the HTML report (snakemake --report report.html, after a run): every report() output of the rules
report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/data.smk"
include: "workflow/rules/fit.smk"
include: "workflow/rules/models.smk"
include: "workflow/rules/dynamics.smk"
include: "workflow/rules/sweeps.smk"
include: "workflow/rules/validation.smk"
include: "workflow/rules/benchmark.smk"
include: "workflow/rules/design.smk"
include: "workflow/rules/report.smk"
include: "workflow/rules/figures.smk"


localrules:
    all,


rule all:
    default_target: True
    input:
        "reports/report.pdf",
        report_figures(),
