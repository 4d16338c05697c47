"""Synthetic benchmark scenes written as SVG files (not part of the test suite)."""

from __future__ import annotations

import math
from pathlib import Path

LEAF_D = "M0,0 Q5,-8 14,-2 Q9,2 0,0 Z"


def rotating_grid_svg(rows: int, cols: int, step: float = 40.0, turn: float = 12.0) -> str:
    """A rows × cols grid of leaves whose rotation grows along each row (baked coordinates)."""
    parts = []
    for r in range(rows):
        for c in range(cols):
            x, y, a = 20 + step * c, 20 + step * r, math.radians(turn * c)
            ca, sa = math.cos(a), math.sin(a)

            def p(u: float, v: float, x=x, y=y, ca=ca, sa=sa) -> str:
                return f"{x + ca * u - sa * v:.4f},{y + sa * u + ca * v:.4f}"

            d = f"M{p(0, 0)} Q{p(5, -8)} {p(14, -2)} Q{p(9, 2)} {p(0, 0)} Z"
            parts.append(f'<path fill="none" stroke="#1b5e20" d="{d}"/>')
    w, h = 40 + step * cols, 40 + step * rows
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}">\n'
        + "\n".join(parts)
        + "\n</svg>\n"
    )


def scattered_svg(n: int, seed: int = 7, size: float = 1000.0, turn: bool = False) -> str:
    """``n`` copies of one triangle at random places (and at random angles if ``turn``)."""
    import random

    rng = random.Random(seed)
    parts = []
    for _ in range(n):
        x, y = rng.uniform(0, size), rng.uniform(0, size)
        a = math.radians(rng.uniform(0, 360)) if turn else 0.0
        ca, sa = math.cos(a), math.sin(a)
        pts = " ".join(
            f"{x + ca * u - sa * v:.4f},{y + sa * u + ca * v:.4f}" for u, v in ((0, 0), (10, 0), (7, 13))
        )
        parts.append(f'<polygon fill="#3949ab" points="{pts}"/>')
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{size}" height="{size}" viewBox="0 0 {size} {size}">\n'
        + "\n".join(parts)
        + "\n</svg>\n"
    )


def blobs_svg(n: int, seed: int = 3, size: float = 2000.0) -> str:
    """``n`` distinct blobs (polygons of 5-30 corners at random radii) at random places: a map."""
    import random

    rng = random.Random(seed)
    parts = []
    for _ in range(n):
        cx, cy, k = rng.uniform(0, size), rng.uniform(0, size), rng.randint(5, 30)
        pts = " ".join(
            f"{cx + r * math.cos(2 * math.pi * j / k):.2f},{cy + r * math.sin(2 * math.pi * j / k):.2f}"
            for j, r in enumerate(rng.uniform(5, 25) for _ in range(k))
        )
        parts.append(
            f'<polygon fill="#{rng.randrange(0xFFFFFF):06x}" stroke="#333" stroke-width="0.5" points="{pts}"/>'
        )
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{size}" height="{size}" viewBox="0 0 {size} {size}">\n'
        + "\n".join(parts)
        + "\n</svg>\n"
    )


def grid_dims(n: int) -> tuple[int, int]:
    """Rows and columns of a roughly 3:4 grid with about ``n`` elements (1200 -> 30 x 40)."""
    rows = max(1, round(math.sqrt(n * 3 / 4)))
    return rows, max(1, round(n / rows))


def write(path: Path, text: str) -> Path:
    path.write_text(text)
    return path
