"""Termination of a grammar's derivation, and drawable path data (see :mod:`.validate`)."""

from __future__ import annotations

import numpy as np

from lsys_core.grammar.model import Grammar, Symbol
from lsys_core.grammar.validate import Problem, count_text

__all__ = ["path_problem", "termination_problems"]


def termination_problems(g: Grammar) -> list[Problem]:
    """Return a problem for every call that lets a derivation loop forever."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    index = {r.name: i for i, r in enumerate(g.rules)}
    calls = [
        (index[r.name], index[mod.name], r, ci, mi, mod)
        for r in g.rules
        for ci, case in enumerate(r.cases)
        for mi, mod in enumerate(case.body)
        if isinstance(mod, Symbol) and mod.name in index
    ]
    if not calls:
        return []

    def scc(edges: list[tuple[int, int]]) -> np.ndarray:
        src, dst = np.array(edges, dtype=int).T
        mat = coo_matrix((np.ones(len(edges)), (src, dst)), shape=(len(index), len(index)))
        return connected_components(mat, directed=True, connection="strong")[1]

    def cyclic(labels: np.ndarray, edges: list[tuple[int, int]]) -> list[bool]:
        """Tell for each edge whether it lies on a cycle (same SCC, or a self-loop)."""
        sizes = np.bincount(labels, minlength=len(index))
        return [labels[u] == labels[v] and (u == v or sizes[labels[u]] > 1) for u, v in edges]

    edges = [(u, v) for u, v, *_ in calls]
    out = []
    zero_calls = []
    for on_cycle, c in zip(cyclic(scc(edges), edges), calls, strict=True):
        _, _, r, ci, mi, mod = c
        if not on_cycle:
            continue
        arg = mod.arg
        call = mod.name + (f"({count_text(arg)})" if arg is not None else "")
        if arg is None:  # well-formed: a call passes a counter exactly when its rule is parametric
            why = f"the call {call} closes a cycle that has no counter to stop it"
        elif arg.k1 != 1 or arg.k0 > 0:
            why = f"the call {call} does not decrease m (write {mod.name}(m-1))"
        else:
            if arg.k0 == 0:
                zero_calls.append(c)
            continue
        out.append(Problem(f"rule {r.name} never terminates: {why}", "rule", r.name, ci, mi))
    if zero_calls:  # m - 0 is fine only if every cycle through it also has a decreasing call
        zedges = [(u, v) for u, v, *_ in zero_calls]
        for on_cycle, (_, _, r, ci, mi, mod) in zip(cyclic(scc(zedges), zedges), zero_calls, strict=True):
            if on_cycle:
                why = f"the call {mod.name}(m) does not decrease m (write {mod.name}(m-1))"
                out.append(Problem(f"rule {r.name} never terminates: {why}", "rule", r.name, ci, mi))
    return out


def path_problem(d: str) -> str | None:
    """Return why terminal path data cannot be drawn, or None.

    Not part of :func:`find_problems`: path data is kept as given, and only a caller that
    is about to draw or export (the ``lsys`` command) insists that it parses.

    Parameters
    ----------
    d : str
        SVG path data; empty data (a terminal that draws nothing) is fine.

    Returns
    -------
    str or None
        ``"invalid path data ..."`` or ``"path data has non-finite or huge coordinates"``.
    """
    from lsys_core.errors import SvgError
    from lsys_core.geometry.paths import MAX_COORD, cubics_from_d

    if not d.strip():
        return None
    try:
        cubics, _, _ = cubics_from_d(d)
    except SvgError as exc:
        return str(exc)
    with np.errstate(invalid="ignore"):
        if cubics.size and not (np.isfinite(cubics).all() and np.abs(cubics).max() <= MAX_COORD):
            return "path data has non-finite or huge coordinates"
    return None
