"""Render the README's pictures from the example gallery (no Qt needed).

    .venv/bin/python docs/images/make_images.py

writes ``docs/images/gallery.png`` (the six example inputs), and for several examples
``NAME-input.png`` (the SVG as it is) beside ``NAME-edited.png`` (the inferred rules, derived
again after changing a parameter or symmetrizing).  The editor screenshot ``editor.png`` is
made by the editor itself: ``lsys-editor resources/examples/helix.svg --screenshot
docs/images/editor.png`` (with ``QT_QPA_PLATFORM=offscreen`` on a machine without display).
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from lsys_core.derive.derivation import derive  # noqa: E402
from lsys_core.derive.model import Drawing  # noqa: E402
from lsys_core.geometry.paths import d_from_cubics  # noqa: E402
from lsys_core.grammar import Grammar, Terminal, parse_grammar, set_params  # noqa: E402
from lsys_core.pipeline import symmetrize  # noqa: E402
from lsys_core.render.raster import default_view, render  # noqa: E402
from lsys_core.svg.parse import load_svg  # noqa: E402

__all__ = ["EDITS", "main"]

EXAMPLES = ROOT / "resources" / "examples"
OUT = ROOT / "docs" / "images"
WHITE = (255, 255, 255, 255)
TILE = 360
GALLERY = ("helix", "branching-plant", "facade", "tiled-ornament", "flower-ring", "jittered-tiles")

#: Parameter changes (``lsys params`` keys of the shipped, inferred rules) shown in the README.
EDITS: dict[str, dict[str, float]] = {
    "helix": {"m": 240, "P1.0.3.v": 0.993},
    "branching-plant": {"m": 8},
    "facade": {"P2.0.1.m": 8, "P2.1.0.m": 8, "P1.0.3.v": 46},
    "tiled-ornament": {"m": 3, "P2.0.1.m": 11, "P2.1.0.m": 11, "P1.0.2.v": 46},
}


def rules(name: str) -> Grammar:
    """Return the shipped, inferred rules of example ``name``."""
    return parse_grammar((EXAMPLES / f"{name}.lsys").read_text(encoding="utf-8"))


def fitted(drawing: Drawing) -> Drawing:
    """Return ``drawing`` without its canvas, so pictures fit what was drawn."""
    return dataclasses.replace(drawing, viewbox=None, size=None)


def scene_drawing(name: str) -> Drawing:
    """Return the example's SVG as a drawing: every element its own terminal, unmoved."""
    scene = load_svg(EXAMPLES / f"{name}.svg")
    terms = tuple(
        Terminal(f"E{i}", d_from_cubics(e.cubics, e.subpaths, e.closed), e.style)
        for i, e in enumerate(scene.elements)
    )
    n = len(terms)
    one = np.ones(n, dtype=complex)
    return Drawing(terms, np.arange(n, dtype=np.int32), one, 0 * one, np.full(n, -1, np.int32))


def picture(drawing: Drawing, width: int, height: int) -> np.ndarray:
    """Render ``drawing`` fitted into a white ``height`` × ``width`` RGBA image."""
    return render(drawing, width, height, view=default_view(fitted(drawing)), background=WHITE)


def save(pixels: np.ndarray, path: Path) -> None:
    """Write an RGBA array as PNG."""
    import skia

    image = skia.Image.fromarray(np.ascontiguousarray(pixels), colorType=skia.ColorType.kRGBA_8888_ColorType)
    path.write_bytes(bytes(image.encodeToData(skia.EncodedImageFormat.kPNG, 100)))


def main() -> int:
    """Write every picture; return the exit status."""
    OUT.mkdir(parents=True, exist_ok=True)
    tiles = [picture(scene_drawing(n), TILE, TILE) for n in GALLERY]
    rows = [np.concatenate(tiles[i : i + 3], axis=1) for i in range(0, len(tiles), 3)]
    save(np.concatenate(rows, axis=0), OUT / "gallery.png")
    for name, values in EDITS.items():
        save(picture(scene_drawing(name), TILE, TILE), OUT / f"{name}-input.png")
        save(picture(derive(set_params(rules(name), values)), TILE, TILE), OUT / f"{name}-edited.png")
    scene = load_svg(EXAMPLES / "jittered-tiles.svg")
    save(picture(scene_drawing("jittered-tiles"), TILE, TILE), OUT / "jittered-tiles-input.png")
    save(picture(derive(symmetrize(scene).grammar), TILE, TILE), OUT / "jittered-tiles-edited.png")
    print(f"wrote pictures to {OUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
