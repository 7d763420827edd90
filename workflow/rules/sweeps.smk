# Sensitivity sweeps of Table 2 (Figs. 7-14) with the paper's parameters, one NetCDF file per
# case, all in one job (each case takes well under a second; one job saves the start-up of the
# others). With sweep_chunks > 1 each case is instead split along the speed axis into chunk jobs
# (for a cluster) and gathered again; the gathered file equals the unchunked one. The analyst's sweeps
# (fitted material) are in fit.smk.

if SWEEP_CHUNKS == 1:

    rule paper_sweeps:
        output:
            expand("results/paper/sweeps/case_{case}.nc", case=SWEEP_CASES),
        log:
            "logs/paper_sweeps.log",
        benchmark:
            "benchmarks/paper_sweeps.tsv"
        conda:
            "../envs/microimpact.yaml"
        threads: 1
        params:
            contact=config["paper_contact"],
            cases=SWEEP_CASES,
            overrides=config["sweeps"],
            rtol=RTOL,
        script:
            "../scripts/sweep.py"

else:

    rule paper_sweep_chunk:
        output:
            "results/paper/sweeps/chunks/case_{case}/chunk_{chunk}_of_{nchunks}.nc",
        log:
            "logs/sweeps/case_{case}_chunk_{chunk}_of_{nchunks}.log",
        benchmark:
            "benchmarks/sweeps/case_{case}_chunk_{chunk}_of_{nchunks}.tsv"
        conda:
            "../envs/microimpact.yaml"
        threads: 1
        params:
            contact=config["paper_contact"],
            overrides=sweep_overrides,
            rtol=RTOL,
        script:
            "../scripts/sweep_chunk.py"

    rule gather_paper_sweep:
        input:
            paper_sweep_chunk_files,
        output:
            "results/paper/sweeps/case_{case}.nc",
        log:
            "logs/sweeps/gather_case_{case}.log",
        benchmark:
            "benchmarks/sweeps/gather_case_{case}.tsv"
        conda:
            "../envs/microimpact.yaml"
        script:
            "../scripts/gather_sweep.py"
