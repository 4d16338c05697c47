"""Derive the application icon from its L-system and write the freedesktop icon theme files.

    python packaging/make_icons.py

reads ``resources/icons/icon.lsys`` and writes ``resources/icons/hicolor/scalable/apps/APP_ID.svg``
and ``resources/icons/hicolor/NxN/apps/APP_ID.png`` for every size in :data:`SIZES`.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lsys_core.derive.derivation import derive  # noqa: E402
from lsys_core.grammar import parse_grammar  # noqa: E402
from lsys_core.render.raster import render_png  # noqa: E402
from lsys_core.render.svg import export_svg  # noqa: E402

__all__ = ["APP_ID", "SIZES", "main"]

APP_ID = "io.github.lsys_editor.LsysEditor"
SIZES = (16, 32, 48, 64, 128, 256)
ICONS = ROOT / "resources" / "icons"


def main() -> int:
    """Write the scalable SVG icon and one PNG per size; return the exit status."""
    drawing = derive(parse_grammar((ICONS / "icon.lsys").read_text(encoding="utf-8")))
    scalable = ICONS / "hicolor" / "scalable" / "apps"
    scalable.mkdir(parents=True, exist_ok=True)
    export_svg(drawing, scalable / f"{APP_ID}.svg")
    for size in SIZES:
        out = ICONS / "hicolor" / f"{size}x{size}" / "apps"
        out.mkdir(parents=True, exist_ok=True)
        render_png(drawing, out / f"{APP_ID}.png", size, size)
    print(f"wrote {APP_ID} icons: scalable, {', '.join(str(s) for s in SIZES)} px")
    return 0


if __name__ == "__main__":
    sys.exit(main())
