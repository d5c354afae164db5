"""``python -m fem_twin.cli``: the ``fem-twin`` command."""

import sys

from .main import main

if __name__ == "__main__":
    sys.exit(main())
