"""``python -m hamilton_orbits``: the same command line as the ``hamilton-orbits`` script."""

import sys

from hamilton_orbits.cli import main

if __name__ == "__main__":  # pragma: no cover - run through a subprocess in the tests
    sys.exit(main())
