"""``python -m lsys_core.cli``: the ``lsys`` command.

When the command has returned, its files are written and closed and nothing of the process
is needed any more: it ends with ``os._exit`` after flushing standard output and error,
without the interpreter's finalisation (freeing every object of numpy, scipy and the
inference one by one, and a last full garbage collection): that took 8 % of the CPU time
of a 0.9 s ``lsys infer`` of 1,200 elements (whole process, 7 pairs).  An exception raised
by :func:`~lsys_core.cli.main` (``LSYS_DEBUG=1``) still ends the process the usual way.
"""

import contextlib
import os
import sys

from lsys_core.cli import main


def _exit_now(status: int) -> None:
    """Flush standard output and error, then end the process with ``status`` at once."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError, AttributeError):
            stream.flush()
    os._exit(status)


if __name__ == "__main__":
    _exit_now(main())
