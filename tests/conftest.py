"""The suite runs numpy's code as the ``lsys`` command and the editor do (see :mod:`lsys_core.cpu`)."""

from lsys_core.cpu import prefer_fast_sort

prefer_fast_sort()
