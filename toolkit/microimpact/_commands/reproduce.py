"""``microimpact reproduce``: the paper's numbers checked by computation."""

from __future__ import annotations

from microimpact.io.paths import check_outputs, reporting_os_errors
from microimpact.studies.reproduction import reproduction_table, write_reproduction_markdown



def run(args) -> int:
    out = check_outputs({"--out": args.out})["--out"]
    table = reproduction_table(time_budget=args.time_budget)
    with reporting_os_errors({"--out": out}):
        write_reproduction_markdown(table, out)
    print(f"wrote {out}")
    return 0
