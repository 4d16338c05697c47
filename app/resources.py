"""Where the bundled resources (examples, icons) are: the checkout, or a frozen bundle."""

from __future__ import annotations

import sys
from pathlib import Path

__all__ = ["APP_ID", "examples", "icon_path", "resource_dir"]

#: The freedesktop/AppStream id, also the desktop file's name.
APP_ID = "io.github.lsys_editor.LsysEditor"


def resource_dir() -> Path | None:
    """Return the ``resources`` folder (PyInstaller's ``_MEIPASS`` first), or None."""
    roots = []
    if getattr(sys, "_MEIPASS", None):
        roots.append(Path(sys._MEIPASS))
    roots.append(Path(__file__).resolve().parents[1])
    for root in roots:
        if (root / "resources").is_dir():
            return root / "resources"
    return None


def examples() -> list[Path]:
    """Return the bundled example SVGs, sorted by name."""
    res = resource_dir()
    return sorted((res / "examples").glob("*.svg")) if res else []


def icon_path() -> Path | None:
    """Return the scalable application icon, if bundled."""
    res = resource_dir()
    path = res / "icons" / "hicolor" / "scalable" / "apps" / f"{APP_ID}.svg" if res else None
    return path if path is not None and path.is_file() else None
