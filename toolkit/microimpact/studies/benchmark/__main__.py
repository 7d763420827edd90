"""``python -m microimpact.studies.benchmark [options]``: the same as ``microimpact benchmark [options]``."""

import sys

from microimpact.cli import main

sys.exit(main(["benchmark", *sys.argv[1:]]))
