"""Files in and out: bounded reading, and writing that never leaves a clobbered file.

Reading (:func:`read_bytes`, :func:`read_text`) checks a size limit before and while
reading, so ``/dev/zero``, an endless pipe or a sparse multi-gigabyte file fail after
at most ``limit`` bytes, and text that is not UTF-8 (or holds NUL bytes) fails on its
first bad chunk.

Writing (:func:`write_files_atomic`) treats each target by its kind:

- a regular file (or a new name) is replaced atomically: data goes to a temporary
  file beside it (a short name, so any name the file system accepts works), is
  flushed to disk and renamed over the target with :func:`os.replace`;
- a symbolic link is written through: its final target is replaced as above and the
  link stays a link;
- a device, FIFO or socket (``/dev/null``, ``/dev/stdout``, a named pipe) is written
  through, never replaced by a regular file;
- an open binary stream or a file descriptor (standard output) is written to.

Nothing is renamed until every stream has been written and every temporary file is
on disk, so a failure (a full disk, ``/dev/full``, a missing folder) leaves every
existing file byte for byte as it was.  :func:`check_outputs` refuses, before any
work, outputs that cannot be written or that are one of the inputs.
"""

from __future__ import annotations

from lsys_core.io.read import CHUNK, MAX_TEXT_BYTES, read_bytes, read_text
from lsys_core.io.write import OutputClosed, Target, check_outputs, write_atomic, write_files_atomic

__all__ = [
    "CHUNK",
    "MAX_TEXT_BYTES",
    "OutputClosed",
    "Target",
    "check_outputs",
    "read_bytes",
    "read_text",
    "write_atomic",
    "write_files_atomic",
]
