"""Loading skia-python, with one readable line when the system cannot load it.

skia-python links against system libraries (``libEGL.so.1``, ``libGL.so.1``,
``libfontconfig.so.1``) that a minimal server may not have.  Only raster output
needs skia; :func:`load_skia` turns the loader's failure into an
:class:`~lsys_core.errors.LsysError` naming the missing library, so SVG and rule
output keep working and PNG output fails with a message a user can act on.
"""

from __future__ import annotations

import re
from types import ModuleType

from lsys_core.errors import LsysError

__all__ = ["load_skia"]

#: Debian/Ubuntu packages of the libraries skia-python is known to load.
PACKAGES = {
    "libEGL.so.1": "libegl1",
    "libGL.so.1": "libgl1",
    "libfontconfig.so.1": "libfontconfig1",
    "libfreetype.so.6": "libfreetype6",
}
_LIBRARY = re.compile(r"([\w.+-]+\.so(?:\.\d+)*)")


def load_skia() -> ModuleType:
    """Import and return the ``skia`` module.

    Raises
    ------
    LsysError
        One line naming the missing system library (and its Debian package when
        known) when ``import skia`` fails.
    """
    try:
        import skia
    except (ImportError, OSError) as exc:
        raise LsysError(_explain(exc)) from None
    return skia


def _explain(exc: BaseException) -> str:
    detail = " ".join(str(exc).split())
    m = _LIBRARY.search(detail)
    if m is not None:
        lib = m.group(1)
        package = PACKAGES.get(lib)
        hint = f" (on Debian or Ubuntu: apt install {package})" if package else ""
        return f"PNG output needs the system library {lib}, which is missing{hint}"
    if isinstance(exc, ModuleNotFoundError):
        return "PNG output needs the Python package skia-python, which is not installed"
    return f"PNG output needs skia-python, which cannot be loaded ({detail[:160]})"
