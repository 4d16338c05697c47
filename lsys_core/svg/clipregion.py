"""Clip paths intersected into one outline, so nested clipping needs no clip path on a clip path.

When an element's own clip path meets its group's (or a viewport's), the reader needs the region
both let through.  :class:`.masking.Definitions` can write it as the pieces of one clip path each
clipped by the other, which SVG allows but not every renderer draws (librsvg 2.54 ignores a clip
path on a clip path's children).  Here the regions are intersected as geometry (skia's path
operations): the result is one ``<path>`` in an ordinary clip path, which every renderer draws.
Pieces that are not path geometry (``<text>``) cannot be intersected so: the caller keeps the
piece-wise form for them, as it does when skia cannot be loaded.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

import numpy as np

from lsys_core.geometry.paths import cubics_from_d

__all__ = ["PIECE", "Region", "intersect_regions", "piece_region", "region_d", "union_regions"]

#: A clip piece written by the reader: path data and an optional clip rule.
PIECE = re.compile(r'^<path d="([^"]*)"(?: clip-rule="(nonzero|evenodd)")?/>$')

Region = Any  # a skia.Path (skia is imported lazily: loading it may fail on a minimal system)


def _skia():
    try:
        import skia
    except (ImportError, OSError):  # a system without the libraries skia-python loads
        return None
    return skia


def piece_region(markup: str) -> Region | None:
    """The region a clip piece lets through (None: not path geometry, or skia unavailable)."""
    skia = _skia()
    got = PIECE.match(markup)
    if skia is None or got is None:
        return None
    cubics, subpaths, _ = cubics_from_d(got.group(1))
    path = skia.Path()
    if got.group(2) == "evenodd":
        path.setFillType(skia.PathFillType.kEvenOdd)
    if not cubics.shape[0] or not np.isfinite(cubics).all():
        return path
    starts = np.ones(cubics.shape[0], dtype=bool)
    starts[1:] = subpaths[1:] != subpaths[:-1]
    for start, seg in zip(starts.tolist(), cubics.tolist(), strict=True):
        if start:
            path.moveTo(seg[0].real, seg[0].imag)
        path.cubicTo(seg[1].real, seg[1].imag, seg[2].real, seg[2].imag, seg[3].real, seg[3].imag)
    return path


def union_regions(regions: list[Region]) -> Region:
    """The region any of ``regions`` lets through."""
    skia = _skia()
    out = skia.Path()
    for r in regions:
        out = skia.Op(out, r, skia.PathOp.kUnion_PathOp)
    return out


def intersect_regions(a: Region, b: Region) -> Region:
    """The region both let through."""
    skia = _skia()
    return skia.Op(a, b, skia.PathOp.kIntersect_PathOp)


def region_d(region: Region, fmt: Callable[[float], str]) -> tuple[str, str]:
    """Path data and clip rule of a region (empty path data: it lets nothing through)."""
    skia = _skia()
    parts = []
    for verb, pts in region:
        xy = [(p.x(), p.y()) for p in pts]
        if verb == skia.Path.Verb.kMove_Verb:
            parts.append("M" + " ".join(f"{fmt(x)} {fmt(y)}" for x, y in xy[:1]))
        elif verb == skia.Path.Verb.kLine_Verb:
            parts.append("L" + " ".join(f"{fmt(x)} {fmt(y)}" for x, y in xy[1:]))
        elif verb in (skia.Path.Verb.kQuad_Verb, skia.Path.Verb.kConic_Verb):
            parts.append("Q" + " ".join(f"{fmt(x)} {fmt(y)}" for x, y in xy[1:]))
        elif verb == skia.Path.Verb.kCubic_Verb:
            parts.append("C" + " ".join(f"{fmt(x)} {fmt(y)}" for x, y in xy[1:]))
        elif verb == skia.Path.Verb.kClose_Verb:
            parts.append("Z")
    rule = "evenodd" if region.getFillType() == skia.PathFillType.kEvenOdd else "nonzero"
    return " ".join(parts), rule
