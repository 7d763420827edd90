"""``python -m microimpact``: the console script (:func:`microimpact._entry.main`) without its installed wrapper."""

import sys

from microimpact._entry import main

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
