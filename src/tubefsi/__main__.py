"""``python -m tubefsi``: the command line (:mod:`tubefsi.cli`)."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
