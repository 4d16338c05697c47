"""Frozen entry point of ``lsys`` (see lsys-editor.spec)."""

import sys

if __name__ == "__main__":
    from lsys_core.cli import main

    sys.exit(main())
