"""The vectorised turtle of the derivation: case selection, interpretation of compiled bodies, chained frames.

All functions work on a batch of pending calls at once (numpy arrays of counters ``m`` and
turtle states ``(a, b, z)``); :mod:`.derivation` drives them level by level.
"""

from __future__ import annotations

import numpy as np

from lsys_core.geometry.transforms import DEG
from lsys_core.grammar.model import COND_EQ0, COND_GT0, Case, Randomize

__all__ = ["Interpreter", "case_masks", "chain_frames", "segmented_exclusive_cumsum"]


def case_masks(rule_cases: tuple[Case, ...], m: np.ndarray) -> list[np.ndarray]:
    """Return, per case, the mask of counters for which it is the first applicable case."""
    taken = m < 0
    masks = []
    for case in rule_cases:
        if case.cond == COND_GT0:
            ok = m > 0
        elif case.cond == COND_EQ0:
            ok = m == 0
        else:
            ok = m >= 0
        mask = ok & ~taken
        taken |= mask
        masks.append(mask)
    return masks


class Interpreter:
    """Interpret compiled bodies for a batch of items."""

    def __init__(self, randomize: Randomize | None) -> None:
        self.rand = randomize if randomize is not None and randomize.active else None
        self.rng = np.random.default_rng(randomize.seed if randomize is not None else 0)

    def run(self, ops, m, a=None, b=None, z=None, perturb: bool = True):
        """Run ``ops`` for counters ``m``; the state starts at ``(a, b, z)`` (identity, 0 if None).

        Returns the state after the last op, the draws ``(op index, op, a, b, z)`` and the
        calls ``(op index, target, m, a, b, z)``.
        """
        n = m.size
        a = np.ones(n, complex) if a is None else a
        b = np.zeros(n, complex) if b is None else b
        z = np.zeros(n) if z is None else z
        stack = []
        draws = []
        calls = []
        rand = self.rand if perturb else None
        for i, op in enumerate(ops):
            kind = op[0]
            if kind == "t":
                _, sym, c0, cd = op
                v = c0 + cd * m if cd else np.full(n, c0)
                if sym == "f":
                    if rand is not None and rand.distance:
                        v = v * (1.0 + self.rng.uniform(-rand.distance, rand.distance, n))
                    b = b + a * v
                elif sym == "*":
                    if rand is not None and rand.scale:
                        v = v * (1.0 + self.rng.uniform(-rand.scale, rand.scale, n))
                    a = a * v
                elif sym == "z":
                    z = z + v
                else:
                    ang = v if sym == "+" else -v
                    if rand is not None and rand.angle:
                        ang = ang + self.rng.uniform(-rand.angle, rand.angle, n)
                    a = a * np.exp(1j * DEG * ang)
            elif kind == "[":
                stack.append((a, b, z))
            elif kind == "]":
                a, b, z = stack.pop()
            elif kind == "draw":
                draws.append((i, op, a, b, z))
            else:
                _, target, k0, k1 = op
                calls.append((i, target, k0 + k1 * m, a, b, z))
        return a, b, z, draws, calls


def segmented_exclusive_cumsum(x: np.ndarray, starts: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """Exclusive cumulative sum of ``x`` restarted at every segment start."""
    cs = np.cumsum(x)
    excl = cs - x
    return excl - np.repeat(excl[starts], lengths)


def chain_frames(A: np.ndarray, B: np.ndarray, starts, lengths) -> tuple[np.ndarray, np.ndarray]:
    """Frames of a chain of steps relative to the chain start: ``F_{k+1} = F_k ∘ (A_k, B_k)``."""
    with np.errstate(divide="ignore", invalid="ignore"):
        logs = np.log(A)
    if np.all(np.isfinite(logs)):
        rel_a = np.exp(segmented_exclusive_cumsum(logs, starts, lengths))
    else:  # a zero scale somewhere: fall back to a loop over step index (vectorised over chains)
        rel_a = np.empty_like(A)
        k = np.arange(A.size) - np.repeat(starts, lengths)
        cur = np.ones(starts.size, complex)
        owner = np.repeat(np.arange(starts.size), lengths)
        for j in range(int(lengths.max(initial=0))):
            sel = k == j
            rel_a[sel] = cur[owner[sel]]
            cur[owner[sel]] = cur[owner[sel]] * A[sel]
    rel_b = segmented_exclusive_cumsum(rel_a * B, starts, lengths)
    return rel_a, rel_b
