"""Print SVG export sizes, flat vs structured, for the real-world and real-art files (not a test).

For every SVG in ``../shared/realworld`` and ``../shared/realart``: the input's size, the flat
export (one baked ``<path>`` per instance) and the structured export (shapes once in
``<defs>``, ``<use>`` instances, a ``<g>`` per rule call) of the inferred rules' derivation,
each as a ratio of the input, and the time to write both.

Run: ``PYTHONPATH=. .venv/bin/python tests/bench/bench_export.py``
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path

from lsys_core.derive.derivation import derive
from lsys_core.errors import LsysError
from lsys_core.pipeline import infer
from lsys_core.render.structured import drawing_to_structured_svg
from lsys_core.render.svg import drawing_to_svg
from lsys_core.svg import parse_svg
from lsys_core.svg.head import read_head

SHARED = Path(__file__).resolve().parents[2].parent / "shared"
#: Files larger than this are left out (the inference of the largest takes minutes).
MAX_INPUT = 200_000


def main() -> None:
    for folder in ("realworld", "realart"):
        files = sorted(p for p in (SHARED / folder).glob("*.svg") if p.stat().st_size <= MAX_INPUT)
        if not files:
            print(f"{folder}: not available")
            continue
        print(
            f"{folder}: {'file':<38} {'input':>8} {'flat':>8} {'struct':>8} {'flat/in':>8} {'struct/in':>9} {'ms':>6}"
        )
        flat_ratios, struct_ratios = [], []
        for path in files:
            data = path.read_bytes()
            try:
                drawing = derive(infer(parse_svg(data)).grammar)
            except LsysError as exc:
                print(f"  {path.name:<38} skipped: {exc}")
                continue
            except Exception as exc:  # a bug elsewhere must not hide the other files' figures
                print(f"  {path.name:<38} skipped: internal error {type(exc).__name__}: {exc}")
                continue
            t = time.perf_counter()
            flat = len(drawing_to_svg(drawing).encode("utf-8"))
            structured = len(drawing_to_structured_svg(drawing, head=read_head(data)).encode("utf-8"))
            ms = (time.perf_counter() - t) * 1000
            flat_ratios.append(flat / len(data))
            struct_ratios.append(structured / len(data))
            print(
                f"  {path.name:<38} {len(data):>8,} {flat:>8,} {structured:>8,} "
                f"{flat / len(data):>8.2f} {structured / len(data):>9.2f} {ms:>6.1f}"
            )
        print(
            f"  median ratio to the input: flat {statistics.median(flat_ratios):.2f}, "
            f"structured {statistics.median(struct_ratios):.2f}; largest: flat {max(flat_ratios):.2f}, "
            f"structured {max(struct_ratios):.2f}"
        )


if __name__ == "__main__":
    main()
