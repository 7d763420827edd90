"""Rule lammps_check: the paper's microsphere as LAMMPS GRANULAR input, run by LAMMPS against
microimpact -> results/lammps/contact.lmp + results/lammps/check.csv (docs/guide/lammps.md)."""

from microimpact._runtime.joblog import log_job

log_job(snakemake)  # noqa: F821  (output to the log; a failure also as one line on the terminal)

from microimpact.io.files import all_or_nothing, atomic_write, write_csv  # noqa: E402
from microimpact.io.lammps import lammps_expressible, lammps_input  # noqa: E402
from microimpact.presets import named_contact  # noqa: E402
from microimpact.studies.lammps_check import verify_lammps  # noqa: E402

contact, source = named_contact(snakemake.params.contact)  # noqa: F821
contact = lammps_expressible(contact)
law = (f"normal_model {contact.normal_model!r}, no damping, tangential_model {contact.tangential_model!r}, "
       f"friction {contact.friction:g}")
text = lammps_input(contact, source=f"{source} (config paper_contact), in LAMMPS's laws: {law}")
table = verify_lammps(text)
table["lammps_version"] = table.attrs["lammps_version"]
table["tolerance"] = table.attrs["tolerance"]
table["parameter_source"] = f"{source}, in LAMMPS's laws ({law})"
print(table.to_string())
if not table.attrs["passed"]:
    raise RuntimeError(f"LAMMPS and microimpact disagree on {int((~table['agrees']).sum())} of {len(table)} impacts "
                       f"beyond {table.attrs['tolerance']:g} (the table is in the log)")
with all_or_nothing():
    with atomic_write(snakemake.output.contact) as f:  # noqa: F821
        f.write(text)
    write_csv(table, snakemake.output.table)  # noqa: F821
