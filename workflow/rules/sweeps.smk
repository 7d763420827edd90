# Sensitivity sweeps of Table 2 (Figs. 7-14), one NetCDF file per case. With sweep_chunks > 1
# each case is split along the speed axis into chunk jobs (for a cluster) and gathered again;
# the gathered file equals the unchunked one.

if SWEEP_CHUNKS == 1:

    rule sweep:
        output:
            "results/sweeps/case_{case}.nc",
        params:
            contact=simulation_contact(),
            spec=lambda wildcards: config["sweeps"][wildcards.case],
        log:
            "logs/sweeps/case_{case}.log",
        benchmark:
            "benchmarks/sweeps/case_{case}.tsv"
        conda:
            "../envs/microimpact.yaml"
        script:
            "../scripts/sweep.py"

else:

    rule sweep_chunk:
        output:
            "results/sweeps/chunks/case_{case}/chunk_{chunk}_of_{nchunks}.nc",
        params:
            contact=simulation_contact(),
            spec=lambda wildcards: config["sweeps"][wildcards.case],
        log:
            "logs/sweeps/case_{case}_chunk_{chunk}_of_{nchunks}.log",
        benchmark:
            "benchmarks/sweeps/case_{case}_chunk_{chunk}_of_{nchunks}.tsv"
        conda:
            "../envs/microimpact.yaml"
        script:
            "../scripts/sweep_chunk.py"

    rule gather_sweep:
        input:
            sweep_chunk_files,
        output:
            "results/sweeps/case_{case}.nc",
        log:
            "logs/sweeps/gather_case_{case}.log",
        benchmark:
            "benchmarks/sweeps/gather_case_{case}.tsv"
        conda:
            "../envs/microimpact.yaml"
        script:
            "../scripts/gather_sweep.py"
