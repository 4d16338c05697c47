"""Rendering parity on real files: the input and its derived drawing, rendered two ways (not a test).

    python tests/bench/bench_parity.py [DIR] [--only NAME,...] [--side PX]

For every SVG of ``DIR`` (default: the public real-art set, ``../shared/realart`` beside the
checkout): infer, derive, then render

* the input with rsvg-convert (librsvg, an independent renderer),
* the derived SVG (structured export) with rsvg-convert,
* the derived drawing with the project's own renderer (skia, ``lsys_core.render.raster``),

all at the same size (longest side ``--side`` pixels), and print per file the share of inked
pixels (alpha >= 128 in either image) whose colour or coverage differs from the input's rendering
(any channel by more than 32 of 255).  Target: <= 2 % for both.  The project's own renderer
draws content kept as is (text laid out with fontconfig's faces, ``data:`` images) and
gradients, clip paths and dashes, at their places in the paint order (``lsys_core.render.kept``);
what it does not draw (patterns, masks, filters) shows up as a difference.  Needs rsvg-convert (Debian:
librsvg2-bin).
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from lsys_core.derive.derivation import derive  # noqa: E402
from lsys_core.errors import LsysError  # noqa: E402
from lsys_core.pipeline import infer  # noqa: E402
from lsys_core.render.raster import render  # noqa: E402
from lsys_core.render.skia_import import load_skia  # noqa: E402
from lsys_core.render.svg import export_svg  # noqa: E402
from lsys_core.svg.parse import load_svg  # noqa: E402

DEFAULT_DIR = ROOT.parent / "shared" / "realart"


def decode(png: bytes) -> np.ndarray:
    """Straight RGBA pixels of a PNG (decoded by skia)."""
    skia = load_skia()
    image = skia.Image.MakeFromEncoded(skia.Data.MakeWithCopy(png))
    return np.asarray(image.toarray(colorType=skia.kRGBA_8888_ColorType, alphaType=skia.kUnpremul_AlphaType))


def rsvg(svg: Path, width: int, height: int) -> np.ndarray:
    """The SVG rendered by rsvg-convert at ``width`` × ``height``."""
    png = subprocess.run(
        ["rsvg-convert", "-w", str(width), "-h", str(height), str(svg)], capture_output=True, check=True
    ).stdout
    return decode(png)


def differing(a: np.ndarray, b: np.ndarray) -> float:
    """Share of inked pixels (either image) whose colour or coverage differs, in %."""
    a, b = a.astype(int), b.astype(int)
    ink = (a[..., 3] >= 128) | (b[..., 3] >= 128)
    diff = (np.abs(a - b).max(axis=-1) > 32) & ink
    return 100.0 * float(diff.sum()) / max(int(ink.sum()), 1)


def size_of(viewbox: tuple[float, float, float, float] | None, side: int) -> tuple[int, int]:
    """Pixel size with the viewBox's aspect ratio and longest side ``side``."""
    if not viewbox or viewbox[2] <= 0 or viewbox[3] <= 0:
        return side, side
    w, h = viewbox[2], viewbox[3]
    k = side / max(w, h)
    return max(1, round(w * k)), max(1, round(h * k))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("dir", nargs="?", default=str(DEFAULT_DIR))
    parser.add_argument("--only", default="", help="comma-separated file stems")
    parser.add_argument("--side", type=int, default=400, help="longest side in pixels (default 400)")
    args = parser.parse_args(argv)
    if shutil.which("rsvg-convert") is None:
        print("rsvg-convert not found (Debian: librsvg2-bin): nothing measured")
        return 0
    files = sorted(Path(args.dir).glob("*.svg"))
    only = {s for s in args.only.split(",") if s}
    if only:
        files = [f for f in files if f.stem in only]
    ok_rsvg = ok_own = 0
    print(f"{'file':30s} {'elements':>8s} {'rsvg %':>7s} {'own %':>7s} {'infer s':>8s}")
    with tempfile.TemporaryDirectory() as tmp:
        for f in files:
            try:
                scene = load_svg(f)
                t = time.perf_counter()
                drawing = derive(infer(scene).grammar)
                seconds = time.perf_counter() - t
            except LsysError as exc:
                print(f"{f.stem:30s} failed: {exc}")
                continue
            out = Path(tmp) / f"{f.stem}.svg"
            export_svg(drawing, out)
            w, h = size_of(drawing.viewbox, args.side)
            reference = rsvg(f, w, h)
            by_rsvg = differing(reference, rsvg(out, w, h))
            by_own = differing(reference, render(drawing, w, h))
            ok_rsvg += by_rsvg <= 2.0
            ok_own += by_own <= 2.0
            print(f"{f.stem:30s} {len(drawing):8d} {by_rsvg:7.2f} {by_own:7.2f} {seconds:8.2f}", flush=True)
    n = len(files)
    print(f"parity: within 2 % of inked pixels: rsvg-convert {ok_rsvg}/{n}, own renderer {ok_own}/{n}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
