"""``python -m lsys_core.cli``: the ``lsys`` command."""

import sys

from lsys_core.cli import main

if __name__ == "__main__":
    sys.exit(main())
