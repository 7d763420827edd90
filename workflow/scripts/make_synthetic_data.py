"""Regenerate data/synthetic_microspheres.csv (SYNTHETIC data, see data/README.md).

    python workflow/scripts/make_synthetic_data.py [OUTPUT.csv]

Thin wrapper: the generating parameters, the seed and the noise model are
microimpact.analysis.synthetic.SYNTHETIC_DEFAULTS (documented in toolkit/microimpact/analysis/synthetic.py;
the material is Table 1 row 2 of microimpact.model.parameters).
Works from the command line and as a Snakemake script (snakemake.output[0]).
"""

import sys
from pathlib import Path

from microimpact.analysis.synthetic import SYNTHETIC_DEFAULTS, write_synthetic_impacts


def main(out: str) -> None:
    path = write_synthetic_impacts(out)
    print(f"wrote {path} (SYNTHETIC, seed {SYNTHETIC_DEFAULTS['seed']})", file=sys.stderr)


if __name__ == "__main__":
    if "snakemake" in globals():
        main(snakemake.output[0])  # noqa: F821
    else:
        default = Path(__file__).resolve().parents[2] / "data" / "synthetic_microspheres.csv"
        main(sys.argv[1] if len(sys.argv) > 1 else str(default))
