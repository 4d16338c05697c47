"""Write ``docs/images/inkscape.png``: the facade's structured SVG export opened in Inkscape.

The script exports ``resources/examples/facade.lsys`` as structured SVG, opens it in Inkscape
with one row of windows (the group ``P1-2``) selected and the *Layers and Objects* panel open,
and saves a picture of the window.  It needs an X display; on a machine without one::

    xvfb-run -a -s "-screen 0 1400x900x24" env QT_QPA_PLATFORM=xcb \\
        .venv/bin/python docs/images/inkscape_screenshot.py

Requirements (Debian: ``apt install inkscape xdotool xvfb``): Inkscape 1.x, ``xdotool`` (to
open the panel with its shortcut, Ctrl+Shift+L) and Qt's xcb platform (to grab the window).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from lsys_core.derive.derivation import derive  # noqa: E402
from lsys_core.grammar import parse_grammar  # noqa: E402
from lsys_core.render.structured import drawing_to_structured_svg  # noqa: E402

WIDTH, HEIGHT = 1400, 820
#: Seconds Inkscape gets to open the file, then to open the panel (generous: the picture is
#: taken once, a slow start would otherwise show an empty window).
START, PANEL = 25.0, 8.0


def main(out: Path = ROOT / "docs" / "images" / "inkscape.png") -> int:
    from PySide6.QtWidgets import QApplication

    grammar = parse_grammar((ROOT / "resources" / "examples" / "facade.lsys").read_text(encoding="utf-8"))
    with tempfile.TemporaryDirectory() as tmp:
        svg = Path(tmp) / "facade.svg"
        svg.write_text(drawing_to_structured_svg(derive(grammar)), encoding="utf-8")
        inkscape = subprocess.Popen(
            ["inkscape", "--with-gui", "--actions=select-by-id:P1-2", str(svg)],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            time.sleep(START)
            window = subprocess.run(
                ["xdotool", "search", "--sync", "--onlyvisible", "--class", "inkscape"],
                capture_output=True,
                text=True,
                timeout=60,
                check=True,
            ).stdout.split()[0]
            subprocess.run(["xdotool", "windowsize", window, str(WIDTH), str(HEIGHT)], check=True, timeout=60)
            subprocess.run(
                ["xdotool", "windowfocus", "--sync", window, "key", "ctrl+shift+l"], check=True, timeout=60
            )
            time.sleep(PANEL)
            app = QApplication.instance() or QApplication([])
            picture = app.primaryScreen().grabWindow(0, 0, 0, WIDTH, HEIGHT)
            if not picture.save(str(out)):
                print(f"cannot write {out}", file=sys.stderr)
                return 1
        finally:
            inkscape.terminate()
            inkscape.wait(30)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
