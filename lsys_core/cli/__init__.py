"""The ``lsys`` command: infer, symmetrize, derive and inspect L-systems without a GUI.

It behaves like a Unix filter: ``-`` names standard input or output (``cat a.svg | lsys
infer - --svg - | …``), options may come before or after the subcommand and its files,
and a closed pipe (``lsys params r.lsys | head -1``) ends the command quietly with the
status of a process killed by ``SIGPIPE`` (141).

Every failure prints one line ``lsys: error: …`` on stderr and exits 1 (2 for usage
errors, 130 when interrupted, 70 for an internal error, i.e. a bug: set ``LSYS_DEBUG=1``
to see its traceback).  File names in messages are quoted like ``ls`` quotes them.
Inputs are read with a size limit checked while reading.  Outputs are checked before any
work starts (an output that is an input is refused, as ``cp`` does), computed in memory,
and written together: regular files atomically, devices, FIFOs and symbolic links
through (see :mod:`lsys_core.io`); a failed run leaves existing files byte for byte
untouched.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import os
import signal
import sys
from collections.abc import Sequence
from typing import NoReturn

from lsys_core.cli.args import build_parser
from lsys_core.cli.commands import Progress, run_command
from lsys_core.cpu import prefer_fast_sort, prefer_small_pages
from lsys_core.errors import LsysError
from lsys_core.io import OutputClosed
from lsys_core.parallel import keep_freed_memory, switching_often
from lsys_core.quoting import printable

__all__ = ["main", "run"]

#: Exit status after a closed pipe: what a shell reports for a process killed by SIGPIPE.
EXIT_PIPE = 128 + int(getattr(signal, "SIGPIPE", 13))


def _say(text: str) -> None:
    """Print one line on stderr, every character that is not printable escaped; ignore a closed stderr."""
    with contextlib.suppress(OSError, ValueError):
        sys.stderr.write(printable(text) + "\n")
        sys.stderr.flush()


def _settle_stdout() -> None:
    """Flush standard output; if that fails (closed pipe, full device) point it at the null device.

    Python flushes ``sys.stdout`` again at exit; without this the failure would be reported
    a second time as "Exception ignored …".
    """
    try:
        sys.stdout.flush()
    except (OSError, ValueError):
        with contextlib.suppress(OSError, ValueError, AttributeError):
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
            os.close(devnull)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``lsys`` command line; returns the exit status."""
    args = build_parser().parse_args(argv)
    keep_freed_memory()  # the command's process is ours: reuse freed arrays (see the function)
    try:
        with switching_often():  # (see the function)
            return _run(args)
    finally:
        gc.unfreeze()  # what the command froze (see commands.frozen_after) is collected again
        _settle_stdout()


def run() -> NoReturn:
    """The ``lsys`` program: :func:`main`, then the end of the process at once.

    When the command has returned, its files are written and closed and nothing of the process
    is needed any more: it ends with ``os._exit`` after flushing standard output and error,
    without the interpreter's finalisation (freeing every object of numpy, scipy and the
    inference one by one, and a last full garbage collection): that took 8 % of the CPU time
    of a 0.9 s ``lsys infer`` of 1,200 elements (whole process, 7 pairs).  An exception raised
    by :func:`main` (``LSYS_DEBUG=1``; ``SystemExit`` of ``--help`` and usage errors) ends the
    process the usual way.  Programs that call :func:`main` themselves keep their process.
    First, before numpy is imported, numpy is told to sort with its AVX2 code where its AVX-512
    sort is slow (:func:`lsys_core.cpu.prefer_fast_sort`) and, in a virtual machine, not to ask
    for huge pages (:func:`lsys_core.cpu.prefer_small_pages`).
    """
    prefer_fast_sort()
    prefer_small_pages()
    status = main()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(OSError, ValueError, AttributeError):
            stream.flush()
    os._exit(status)


def _run(args: argparse.Namespace) -> int:
    progress = Progress(enabled=not args.quiet and sys.stderr.isatty())
    try:
        return run_command(args, progress, _say)
    except (OutputClosed, BrokenPipeError):
        progress.close()
        return EXIT_PIPE
    except LsysError as e:
        progress.close()
        _say(f"lsys: error: {e}")
        return 1
    except KeyboardInterrupt:
        progress.close()
        _say("lsys: error: interrupted")
        return 130
    except MemoryError:
        progress.close()
        _say("lsys: error: out of memory")
        return 1
    except RecursionError:
        progress.close()
        _say("lsys: error: the input is nested too deeply")
        return 1
    except Exception as e:  # a bug: one line for the user, the traceback on request
        progress.close()
        if os.environ.get("LSYS_DEBUG"):
            raise
        detail = " ".join(str(e).split())[:200]
        _say(
            f"lsys: error: internal error ({type(e).__name__}: {detail}); "
            "please report this bug (LSYS_DEBUG=1 shows the traceback)"
        )
        return 70
