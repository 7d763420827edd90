"""``python -m microimpact.studies.benchmark``: runs :func:`microimpact.studies.benchmark.cli.main`."""

import sys

from microimpact.studies.benchmark.cli import main

sys.exit(main())
