"""Where the bundled resources (examples, icons) are: installed package, frozen bundle or checkout."""

from __future__ import annotations

import sys
from pathlib import Path

__all__ = ["APP_ID", "examples", "icon_path", "resource_dir"]

#: The freedesktop/AppStream id, also the desktop file's name.
APP_ID = "io.github.lsys_editor.LsysEditor"


def resource_dir() -> Path | None:
    """Return the ``resources`` folder, or None.

    Looked up in a PyInstaller bundle (``_MEIPASS``), then inside the package (where
    ``pip install`` puts it: ``lsys_editor/resources``), then in the checkout beside ``app/``.
    """
    here = Path(__file__).resolve().parent
    candidates = []
    if getattr(sys, "_MEIPASS", None):
        candidates.append(Path(sys._MEIPASS) / "resources")
    candidates += [here / "resources", here.parent / "resources"]
    for folder in candidates:
        if (folder / "examples").is_dir():
            return folder
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
