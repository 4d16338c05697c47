"""Settings numpy reads when it is imported, chosen for the machine: sorting code and page size.

**Sorting on AMD Zen 4.**  numpy sorts, argsorts and partitions numbers with x86-simd-sort.  Its
AVX-512 code writes every
partitioned vector with the memory form of ``VPCOMPRESSQ``, which AMD's family 19h (Zen 4) runs
in microcode ("avoid the memory destination form of COMPRESS instructions", AMD's optimisation
guide for Zen 4, §2.11.2); OpenJDK turns its AVX-512 sort off on the same processors.  On the
2-core Zen 4 machines that run this project (numpy 2.4), per 10^6 int64 values: ``np.sort``
51 ms with AVX-512 against 10 ms with AVX2, ``np.argsort`` 77 against 27 ms, ``np.partition``
of floats 10 against 1.5 ms.  Sorting took 30 % of the CPU time of an inference: a 50,052-leaf
grid took 11.35 s with one job, 8.26 s without numpy's AVX-512 code (5 alternating pairs,
whole process), the same rules.  Elementwise functions lose little (``np.exp`` of 10^6
floats 0.8 against 4.1 ms; ``np.cos`` the same), and the inference calls them far less.

numpy chooses its code once, when it is first imported, from the environment variable
``NPY_DISABLE_CPU_FEATURES``.  :func:`prefer_fast_sort` sets it, before numpy is imported, on
AMD processors of family 19h when numpy's feature groups are those of numpy ≥ 2.4 (``X86_V4``,
``AVX512_ICL``, ``AVX512_SPR``; other versions are left alone).  A variable already set, even
to nothing, is the user's choice and is kept.  The ``lsys`` command and the editor call it
first thing; a program that uses the library decides for its own process.

**Huge pages in a virtual machine.**  numpy asks the kernel for huge pages (2 MiB) for every
array of 4 MiB or more (``madvise``).  In a virtual machine a huge page is a block of memory
the host may have taken back while it was free, and giving it to the guest again is dear: on
the 2-core virtual machines that run this project, a 50,052-leaf grid spent 1.25 s of system
CPU with huge pages and 0.42 s without, for the same user time (one job, whole ``lsys infer``,
5 alternating pairs: 8.56 -> 7.76 s; two jobs 1.02x, 100,010 leaves with two jobs 12.61 ->
12.02 s).  :func:`prefer_small_pages` sets numpy's ``NUMPY_MADVISE_HUGEPAGE`` to ``0`` there
(a processor that says it runs under a hypervisor), before numpy is imported and unless set;
called beside :func:`prefer_fast_sort`.
"""

from __future__ import annotations

import functools
import importlib.util
import os
import platform
import re
import sys
from collections.abc import MutableMapping
from pathlib import Path

__all__ = [
    "FEATURES",
    "HUGEPAGE",
    "VARIABLE",
    "in_virtual_machine",
    "numpy_version",
    "prefer_fast_sort",
    "prefer_small_pages",
    "slow_compress_store",
]

#: The environment variable numpy reads its disabled features from when it is imported.
VARIABLE = "NPY_DISABLE_CPU_FEATURES"
#: numpy's (≥ 2.4) dispatch groups that use AVX-512: without them numpy sorts with AVX2.
FEATURES = "X86_V4 AVX512_ICL AVX512_SPR"
#: The first numpy whose dispatch groups are :data:`FEATURES`.
FIRST_NUMPY = (2, 4)
#: The environment variable numpy reads whether to ask for huge pages from (``0``: not).
HUGEPAGE = "NUMPY_MADVISE_HUGEPAGE"
#: AMD's family 19h: Zen 3 (no AVX-512, unaffected) and Zen 4.
_ZEN4_FAMILY = 0x19


def slow_compress_store(description: str) -> bool:
    """Whether a processor described like ``/proc/cpuinfo`` (Linux) or ``platform.processor()``
    (Windows: ``AMD64 Family 25 Model 17 Stepping 1, AuthenticAMD``) is an AMD of family 19h.
    """
    if "AuthenticAMD" not in description:
        return False
    m = re.search(r"(?im)^cpu family\s*:\s*(\d+)", description) or re.search(r"\bFamily (\d+)\b", description)
    return m is not None and int(m.group(1)) == _ZEN4_FAMILY


def numpy_version() -> tuple[int, int] | None:
    """The installed numpy's ``(major, minor)``, read from ``numpy/version.py`` without importing numpy."""
    try:
        spec = importlib.util.find_spec("numpy")
        if spec is None or spec.origin is None:
            return None
        text = (Path(spec.origin).parent / "version.py").read_text(encoding="utf-8")
    except (OSError, ValueError, ImportError):
        return None
    m = re.search(r'(?m)^version\s*=\s*["\'](\d+)\.(\d+)', text)
    return (int(m.group(1)), int(m.group(2))) if m else None


@functools.cache
def _processor() -> str:
    """This machine's processor description (empty where it cannot be read); read once."""
    if sys.platform.startswith("linux"):
        try:
            with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as f:
                return f.read(8192).split("\n\n", 1)[0]  # the first processor is enough
        except OSError:
            return ""
    return platform.processor() if sys.platform == "win32" else ""


def _unset(environ: MutableMapping[str, str] | None, name: str) -> MutableMapping[str, str] | None:
    """The environment (``os.environ`` by default) if numpy's variable ``name`` may still be set in it.

    None when it is already set (even to nothing: the user's choice) or, for ``os.environ``,
    when numpy is already imported (it read its variables then).
    """
    env = os.environ if environ is None else environ
    return None if name in env or (environ is None and "numpy" in sys.modules) else env


def prefer_fast_sort(
    environ: MutableMapping[str, str] | None = None,
    processor: str | None = None,
    version: tuple[int, int] | None = None,
) -> bool:
    """Set :data:`VARIABLE` to :data:`FEATURES` if numpy's AVX-512 sort would be slow here.

    Parameters
    ----------
    environ : mapping, optional
        The environment to change (``os.environ``).
    processor : str, optional
        The processor's description (this machine's).
    version : tuple of int, optional
        numpy's ``(major, minor)`` (the installed one's).

    Returns
    -------
    bool
        Whether the variable was set.  Not when numpy is already imported (too late), when the
        variable is already set, on other processors, or with another numpy.
    """
    env = _unset(environ, VARIABLE)
    if env is None or not slow_compress_store(_processor() if processor is None else processor):
        return False
    found = numpy_version() if version is None else version
    if found is None or found < FIRST_NUMPY:
        return False
    env[VARIABLE] = FEATURES
    return True


def in_virtual_machine(description: str) -> bool:
    """Whether a processor described like ``/proc/cpuinfo`` says it runs under a hypervisor."""
    m = re.search(r"(?im)^flags\s*:(.*)$", description)
    return m is not None and "hypervisor" in m.group(1).split()


def prefer_small_pages(environ: MutableMapping[str, str] | None = None, processor: str | None = None) -> bool:
    """Set :data:`HUGEPAGE` to ``0`` in a virtual machine (see the module docstring).

    Parameters
    ----------
    environ : mapping, optional
        The environment to change (``os.environ``).
    processor : str, optional
        The processor's description (this machine's).

    Returns
    -------
    bool
        Whether the variable was set.  Not when numpy is already imported, when the variable
        is already set, or outside a virtual machine (where huge pages are cheap).
    """
    env = _unset(environ, HUGEPAGE)
    if env is None or not in_virtual_machine(_processor() if processor is None else processor):
        return False
    env[HUGEPAGE] = "0"
    return True
