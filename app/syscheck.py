"""Check, before Qt starts, that the system libraries of Qt's platform plugin are installed.

On a fresh Linux desktop Qt's ``xcb`` plugin (X11) needs libraries that a minimal system lacks
(``libxcb-cursor0``, ``libxcb-icccm4``, ``libxcb-keysyms1``, …).  Without them Qt aborts with a
long message that names only the first.  :func:`missing_packages` asks the dynamic linker
(``ldd``) which libraries of the plugin Qt will load are not found, and :func:`problem` turns
them into one ``apt-get install`` line that fixes all of them at once.

``python -m lsys_editor.syscheck`` prints that line and exits 1 when something is missing
(``make run`` runs it first); the editor runs the same check at start-up.  It imports no Qt.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

__all__ = ["debian_package", "main", "missing_libraries", "missing_packages", "platform_plugins", "problem"]

#: Debian packages whose name does not follow the soname rule of :func:`debian_package`.
_PACKAGE_EXCEPTIONS = {
    "libglib-2.0.so.0": "libglib2.0-0",
    "libgthread-2.0.so.0": "libglib2.0-0",
    "libgobject-2.0.so.0": "libglib2.0-0",
    "libX11.so.6": "libx11-6",
    "libGLX.so.0": "libglx0",
    "libOpenGL.so.0": "libopengl0",
}
_NOT_FOUND = re.compile(r"^\s*(\S+)\s*=>\s*not found", re.MULTILINE)


def debian_package(soname: str) -> str:
    """Return the Debian/Ubuntu package that provides the library ``soname``.

    The rule is Debian's library packaging policy: ``libxcb-icccm.so.4`` → ``libxcb-icccm4``,
    ``libxkbcommon-x11.so.0`` → ``libxkbcommon-x11-0`` (a dash when the name ends in a digit),
    lower case; a few exceptions are listed.
    """
    if soname in _PACKAGE_EXCEPTIONS:
        return _PACKAGE_EXCEPTIONS[soname]
    m = re.match(r"^(lib[^/]+?)\.so\.(\d+)", soname)
    if not m:
        return soname
    name, major = m.group(1).lower(), m.group(2)
    return f"{name}-{major}" if name[-1].isdigit() else f"{name}{major}"


def platform_plugins(env: dict[str, str] | None = None) -> list[str]:
    """Return the platform plugins Qt will try, in order (empty: none that needs checking).

    ``QT_QPA_PLATFORM`` decides when set (``offscreen``, ``vnc`` … need nothing); otherwise a
    Wayland session tries ``wayland`` then ``xcb``, and an X11 session ``xcb``.
    """
    env = dict(os.environ if env is None else env)
    chosen = env.get("QT_QPA_PLATFORM", "").strip()
    if chosen:
        names = [part.split(":", 1)[0].strip() for part in chosen.split(";")]
    elif env.get("WAYLAND_DISPLAY") or env.get("XDG_SESSION_TYPE") == "wayland":
        names = ["wayland", "xcb"]
    elif env.get("DISPLAY"):
        names = ["xcb"]
    else:
        names = []
    return [n for n in names if n in ("xcb", "wayland")]


def _plugins_dir() -> Path | None:
    try:
        import PySide6
    except ImportError:
        return None
    base = Path(PySide6.__file__).resolve().parent
    for candidate in (base / "Qt" / "plugins" / "platforms", base / "plugins" / "platforms"):
        if candidate.is_dir():
            return candidate
    return None


def missing_libraries(plugin: str, plugins_dir: Path | None = None) -> list[str] | None:
    """Return the sonames the plugin ``plugin`` needs and the system lacks (None: cannot tell)."""
    plugins_dir = plugins_dir or _plugins_dir()
    ldd = shutil.which("ldd")
    if plugins_dir is None or ldd is None or not sys.platform.startswith("linux"):
        return None
    files = sorted(plugins_dir.glob(f"libq{plugin}*.so"))
    if not files:
        return None
    try:
        out = subprocess.run([ldd, *map(str, files)], capture_output=True, text=True, timeout=30).stdout
    except (OSError, subprocess.SubprocessError):
        return None
    return sorted(set(_NOT_FOUND.findall(out)))


def missing_packages(env: dict[str, str] | None = None) -> tuple[str, list[str]] | None:
    """Return ``(plugin, packages to install)`` when no platform plugin Qt would try can load.

    None when one of them has all its libraries (or the check does not apply).
    """
    first: tuple[str, list[str]] | None = None
    for plugin in platform_plugins(env):
        libs = missing_libraries(plugin)
        if not libs:  # complete, or nothing to tell: Qt will report its own problems
            return None
        packages = sorted({debian_package(lib) for lib in libs})
        if first is None or plugin == "xcb":
            first = (plugin, packages)
    return first


def problem(env: dict[str, str] | None = None) -> str | None:
    """Return the one message naming the fix, or None when Qt's platform plugin can load."""
    found = missing_packages(env)
    if found is None:
        return None
    plugin, packages = found
    return (
        f"Qt's {plugin} platform plugin needs system libraries that are not installed. "
        f"Install them with:\n    sudo apt-get install {' '.join(packages)}\n"
        "(on other distributions, the packages of the same names; --screenshot also works without "
        "a display with QT_QPA_PLATFORM=offscreen)"
    )


def main() -> int:
    """Print the fix and return 1 when libraries are missing, else return 0 silently."""
    message = problem()
    if message:
        print(f"lsys-editor: {message}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
