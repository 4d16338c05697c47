"""Generate scenes of the corpus' kinds with random parameters, to check the kinds, not the files.

    python tests/bench/make_variants.py OUT_DIR [--seeds N]
    python ../shared/tools/score_corpus.py OUT_DIR --lsys .venv/bin/lsys

Each scene is written as SVG (baked coordinates, transform attributes, nested groups or
<use>, chosen per scene) with a JSON of ground truth in the corpus' format.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np

SHAPES = {
    "leaf": "M0,0 Q5,-8 14,-2 Q9,2 0,0 Z",
    "hook": "M0,0 L0,18 C0,24 8,26 10,20 L7,18",
    "flag": "M0,0 L0,20 L12,15 L0,11",
    "window": "M0,0 L10,0 L10,14 L0,14 Z M-1,14 L11,14 L11,16 L-1,16 Z",
    "blade": "M0,0 C4,-1.5 11.5,-3 19.25,-3.375 C27,-3.75 35,-3 40,0 C35,2 28.5,3.25 21.5,3.375 C14.5,3.5 7,2.5 0,0 Z",
}
STYLE = 'fill="none" stroke="#1b5e20" stroke-width="1"'


def mat(x, y, h, s, flip=False):
    a = s * np.exp(1j * np.radians(h))
    fy = -1 if flip else 1
    return (a.real, a.imag, -a.imag * fy, a.real * fy, x, y)


def transform_pts(d: str, m) -> str:
    out, nums = [], []
    import re

    toks = re.findall(r"[A-Za-z]|-?\d*\.?\d+(?:e-?\d+)?", d)
    for t in toks:
        if t.isalpha():
            out.append(t)
        else:
            nums.append(float(t))
            if len(nums) == 2:
                x, y = nums
                out.append(f"{m[0] * x + m[2] * y + m[4]:.4f},{m[1] * x + m[3] * y + m[5]:.4f}")
                nums = []
    return " ".join(out)


def write_scene(out: Path, name: str, items, mode: str, truth: dict, rng) -> None:
    """items: list of (shape, (x, y, heading, scale), flip)."""
    body = []
    defs = set()
    for k, (shape, (x, y, h, s), flip) in enumerate(items):
        m = mat(x, y, h, s, flip)
        d = SHAPES[shape]
        md = mode if mode != "mixed" else ["baked", "transform", "groups"][k % 3]
        if md == "baked":
            body.append(f'<path {STYLE} d="{transform_pts(d, m)}"/>')
        elif md == "transform":
            body.append(f'<path {STYLE} transform="matrix({",".join(f"{v:.4f}" for v in m)})" d="{d}"/>')
        elif md == "groups":
            r = m[:4]
            body.append(
                f'<g transform="translate({x:.4f} {y:.4f})"><g transform="matrix({",".join(f"{v:.4f}" for v in r)},0,0)">'
                f'<path {STYLE} d="{d}"/></g></g>'
            )
        else:  # use
            defs.add(shape)
            body.append(
                f'<use href="#{shape}" {STYLE} transform="matrix({",".join(f"{v:.4f}" for v in m)})"/>'
            )
    xs = np.array([it[1][0] for it in items])
    ys = np.array([it[1][1] for it in items])
    pad = 40
    vb = (xs.min() - pad, ys.min() - pad, xs.max() - xs.min() + 2 * pad, ys.max() - ys.min() + 2 * pad)
    head = (
        f'<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
        f'width="{vb[2]:.4f}" height="{vb[3]:.4f}" viewBox="{" ".join(f"{v:.4f}" for v in vb)}">\n'
    )
    d = "".join(f'<path id="{s}" d="{SHAPES[s]}"/>' for s in sorted(defs))
    text = head + (f"<defs>{d}</defs>\n" if d else "") + "\n".join(body) + "\n</svg>\n"
    (out / f"{name}.svg").write_text(text)
    truth = dict(truth, name=name, elements=len(items), mode=mode)
    (out / f"{name}.json").write_text(json.dumps(truth))


def seq(n, x, y, h, s, step):
    al, d, sc, be = step
    a, b = s * np.exp(1j * np.radians(h)), complex(x, y)
    out = []
    for _ in range(n):
        out.append((b.real, b.imag, math.degrees(np.angle(a)), abs(a)))
        b = b + a * np.exp(1j * np.radians(al)) * d
        a = a * sc * np.exp(1j * np.radians(al + be))
    return out


def kinds(rng):
    r = rng.uniform
    shape = rng.choice(list(SHAPES)[:3])
    mode = rng.choice(["baked", "transform", "groups", "use"])
    yield (
        "sequence",
        [
            (shape, p, False)
            for p in seq(int(rng.integers(4, 9)), 100, 100, r(-90, 90), 1, (0, r(25, 50), 1, 0))
        ],
        mode,
        dict(max_rules=2, tol=0.005),
    )
    yield (
        "helix",
        [
            (shape, p, False)
            for p in seq(
                int(rng.integers(60, 160)), 400, 400, r(0, 360), 1, (0, r(18, 30), r(0.985, 0.995), r(6, 14))
            )
        ],
        mode,
        dict(max_rules=2, tol=0.005),
    )
    k = int(rng.integers(6, 16))
    rad = r(40, 90)
    yield (
        "ring",
        [
            (
                shape,
                (
                    300 + rad * math.cos(2 * math.pi * i / k),
                    300 + rad * math.sin(2 * math.pi * i / k),
                    360 * i / k + 90,
                    1,
                ),
                False,
            )
            for i in range(k)
        ],
        mode,
        dict(max_rules=2, tol=0.005),
    )
    rows, cols = int(rng.integers(3, 9)), int(rng.integers(4, 12))
    dx, dy = r(25, 40), r(30, 45)
    yield (
        "grid",
        [(shape, (20 + dx * c, 20 + dy * rr, 0, 1), False) for rr in range(rows) for c in range(cols)],
        mode,
        dict(max_rules=4, tol=0.005),
    )
    turn = r(5, 20)
    rows, cols = int(rng.integers(4, 10)), int(rng.integers(6, 15))
    yield (
        "rot_grid",
        [(shape, (20 + 40 * c, 20 + 40 * rr, turn * c, 1), False) for rr in range(rows) for c in range(cols)],
        "baked",
        dict(max_rules=6, tol=0.005),
    )
    n = int(rng.integers(5, 12))
    other = "hook" if shape != "hook" else "leaf"
    pts = seq(2 * n, 60, 100, 0, 1, (0, r(20, 35), 1, 0))
    yield (
        "alternating",
        [((shape if i % 2 == 0 else other), p, False) for i, p in enumerate(pts)],
        mode,
        dict(max_rules=3, tol=0.005),
    )
    n = int(rng.integers(5, 12))
    items = []
    for i in range(n):
        x = 40 + 35 * i
        items += [("flag", (x, 120, 0, 1), False), ("flag", (x, 128, 0, 1), True)]
    yield "mirrored", items, "transform", dict(max_rules=4, tol=0.005)
    items = []
    sp = r(60, 80)
    for i in range(int(rng.integers(4, 8))):
        x = 80 + sp * i
        items += [
            ("flag", (x, 300, -90, 1), False),
            ("leaf", (x, 280, -30, 0.8), False),
            ("leaf", (x, 280, -150, 0.8), False),
        ]
    yield "flowers", items, "groups", dict(max_rules=5, tol=0.005)
    # Branching R(depth)
    t1 = (r(-35, -15), r(40, 70), r(0.65, 0.8), r(-10, 10))
    t2 = (r(10, 35), r(80, 130), r(0.6, 0.75), r(-15, 5))
    depth = int(rng.integers(3, 6))
    items = []

    def grow(x, y, h, s, m):
        items.append((shape, (x, y, h, s), False))
        if m == 0:
            return
        for al, d, sc, be in (t1, t2):
            a = s * np.exp(1j * np.radians(h))
            b = complex(x, y) + a * np.exp(1j * np.radians(al)) * d
            grow(b.real, b.imag, h + al + be, s * sc, m - 1)

    grow(100, 400, -80, 1, depth)
    yield "branching", items, mode, dict(max_rules=3, tol=0.005)
    items = [
        (shape, (r(0, 600), r(0, 400), r(0, 360), r(0.4, 1.1)), False)
        for _ in range(int(rng.integers(10, 30)))
    ]
    yield "clutter", items, "mixed", dict(max_rules=None, tol=0.005)
    n = int(rng.integers(20, 40))
    jit = r(0.3, 0.8)
    items = [
        (shape, (20 + 25 * i + rng.normal(0, jit), 200 + rng.normal(0, jit), rng.normal(0, 1.0), 1), False)
        for i in range(n)
    ]
    yield "noisy_sequence", items, "transform", dict(max_rules=3, tol=0.03, jitter=True, symmetrize=True)
    items = []
    for blk in range(2):
        for fl in range(3):
            for w in range(3):
                items.append(
                    (
                        "window",
                        (
                            20 + 120 * blk + 23 * w + rng.normal(0, 0.7),
                            20 + 30 * fl + rng.normal(0, 0.7),
                            rng.normal(0, 1.2),
                            1,
                        ),
                        False,
                    )
                )
    yield "facade_jitter", items, "baked", dict(max_rules=8, tol=0.03, jitter=True, symmetrize=True)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--first", type=int, default=0, help="first seed offset")
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    for seed in range(a.seeds):
        rng = np.random.default_rng(1000 + a.first + seed)
        for kind, items, mode, truth in kinds(rng):
            write_scene(out, f"{kind}_{seed}", items, mode, truth, rng)


if __name__ == "__main__":
    main()
