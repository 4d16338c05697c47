"""Frozen entry point of ``lsys-editor`` (see lsys-editor.spec)."""

import multiprocessing
import sys

if __name__ == "__main__":
    multiprocessing.freeze_support()  # the editor's inference worker re-enters here with spawn
    from lsys_editor.__main__ import main

    sys.exit(main())
