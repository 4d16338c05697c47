"""Render imported scenes directly (elements + definitions + content kept as is) and compare (not a test).

Checks the input side alone: each SVG is read into a Scene, the Scene is written back as SVG in
paint order, and both are rendered with rsvg-convert; the share of inked pixels that differ is
printed per file.  Needs rsvg-convert and the scorer helpers of ../shared/tools.

Run: ``PYTHONPATH=. .venv/bin/python tests/bench/scene_parity.py DIR_OR_FILES... [--only REGEX]``
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
from collections import Counter
from pathlib import Path

from lsys_core.errors import LsysError
from lsys_core.geometry.paths import d_from_cubics
from lsys_core.svg import load_svg
from lsys_core.svg.model import Scene

TOOLS = Path(__file__).resolve().parents[2].parent / "shared" / "tools"


def scene_svg(scene: Scene) -> str:
    """Write a scene as SVG: its canvas, definitions, then elements and kept content in paint order."""
    attrs = ['xmlns="http://www.w3.org/2000/svg"']
    if scene.viewbox:
        attrs.append('viewBox="' + " ".join(f"{v:.10g}" for v in scene.viewbox) + '"')
    if scene.size:
        attrs += [f'width="{scene.size[0]}"', f'height="{scene.size[1]}"']
    items = []
    for e in scene.elements:
        d = d_from_cubics(e.cubics, e.subpaths, e.closed)
        items.append((e.order, f'<path d="{d}" style="{e.style}"/>'))
    items += [(v.order, v.xml) for v in scene.verbatim]
    body = "\n".join(x for _, x in sorted(items, key=lambda t: t[0]))
    return f"<svg {' '.join(attrs)}>\n<defs>{scene.defs}</defs>\n{body}\n</svg>\n"


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("paths", nargs="+")
    ap.add_argument("--only", default="")
    ap.add_argument("--keep", help="folder to keep the written scenes in")
    a = ap.parse_args()
    sys.path.insert(0, str(TOOLS))
    from score_realart import pixel_diff  # type: ignore[import-not-found]

    files = []
    for p in map(Path, a.paths):
        files += sorted(p.rglob("*.svg")) if p.is_dir() else [p]
    files = [f for f in files if re.search(a.only, str(f))]
    verdicts: Counter = Counter()
    with tempfile.TemporaryDirectory() as tmp:
        out_dir = Path(a.keep) if a.keep else Path(tmp)
        out_dir.mkdir(parents=True, exist_ok=True)
        for f in files:
            try:
                scene = load_svg(f)
            except LsysError as exc:
                print(f"refused  {f}  {exc}")
                verdicts["refused"] += 1
                continue
            out = out_dir / (f.stem + ".scene.svg")
            out.write_text(scene_svg(scene))
            pix = pixel_diff(str(f), str(out))
            verdict = "skipped" if pix is None else ("ok" if pix <= 2.0 else "differs")
            verdicts[verdict] += 1
            print(f"{verdict:<8} {f}  {'' if pix is None else f'{pix:.1f} %'}", flush=True)
    print(" ".join(f"{k} {v}" for k, v in sorted(verdicts.items())))
    return 0


if __name__ == "__main__":
    sys.exit(main())
