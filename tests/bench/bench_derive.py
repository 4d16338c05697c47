"""Derivation and SVG export throughput (elements per second), median of several runs."""

from __future__ import annotations

import os
import statistics
import tempfile
import time
from pathlib import Path

from lsys_core.derive.derivation import derive
from lsys_core.grammar import parse_grammar
from lsys_core.render.svg import export_svg

HEAD = 'lsys 1\nterminal A "M0 0 C3 -5 8 -6 14 -2 C10 1 6 1 0 0 Z"\n'
CASES = {
    "helix P(336)": HEAD
    + "axiom: P(336)\nP(m): m > 0 -> A f(27.5) *(0.993) +(8.5) P(m-1)\nP(m): m == 0 -> A\n",
    "helix P(999999)": HEAD + "axiom: P(999999)\nP(m): m > 0 -> A f(27.5) *(0.99999) +(8.5) P(m-1)\n"
    "P(m): m == 0 -> A\n",
    "branching R(16)": HEAD + "axiom: R(16)\nR(m): m > 0 -> A [ -(17) f(64) *(0.8) -(3) R(m-1) ] "
    "[ +(7) f(181) *(0.6) +(23) R(m-1) ]\nR(m): m == 0 -> A\n",
    "grid 300x334": HEAD + "axiom: Q(299)\nP(m): m > 0 -> A f(20) P(m-1)\nP(m): m == 0 -> A\n"
    "Q(m): m > 0 -> [ P(333) ] +(90) f(20) -(90) Q(m-1)\nQ(m): m == 0 -> P(333)\n",
}


def timed(fn, repeats: int = 5) -> float:
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main() -> None:
    print(f"derivation benchmark ({os.cpu_count()} cores, median of 5)")
    print(f"{'grammar':<18} {'elements':>10} {'derive ms':>10} {'elements/s':>14}")
    for name, text in CASES.items():
        g = parse_grammar(text)
        n = len(derive(g))
        t = timed(lambda g=g: derive(g))
        print(f"{name:<18} {n:>10,} {t * 1000:>10.1f} {n / t:>14,.0f}")
    g = parse_grammar(CASES["branching R(16)"])
    d = derive(g)
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "o.svg"
        t = timed(lambda: export_svg(d, out), 3)
    print(f"SVG export of {len(d):,} elements: {t * 1000:.0f} ms")


if __name__ == "__main__":
    main()
