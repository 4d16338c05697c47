"""Make an inferred grammar paint like its input: paint order, per-instance styles, names.

The hierarchy writes rules for the geometry only.  Here the grammar is derived once, each
derived instance is matched to the input element it reproduces, and the grammar is given
what the elements' paint needs:

- **strokes** — a terminal whose instances' stroke widths (and dashes) are proportional to
  their scale, as when each copy was drawn with a scaling ``transform``, is marked
  ``scaled``: one style in its own units serves every instance;
- **styles** — every terminal occurrence whose instances share one style gets it
  (``A{s2}``, nothing when it is the terminal's own base style); when the instances differ
  only in numbers linear in the rule's counter (opacity fading, stroke width growing), the
  numbers become paint properties (``A{opacity: 0.1 + 0.07*m}``); any other instance keeps its
  own style through the ``paint:`` table;
- **paint order** — when the derived order differs from the document's, each occurrence
  whose instances' document positions are linear in the counter gets a paint-order value
  (``A{z: 4 + 2*m}``), and if that still does not give the document order, the ``order:``
  table lists every instance's place.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import replace

import numpy as np

from lsys_core.derive.derivation import Trace
from lsys_core.derive.model import Drawing
from lsys_core.derive.paint import css_decls, css_text
from lsys_core.grammar.model import Grammar, Linear, Module, NamedStyle, Paint, Symbol

__all__ = ["fit_paint", "match_instances"]

#: Style properties whose numbers may progress linearly along a rule (become paint properties).
_NUMERIC = ("opacity", "fill-opacity", "stroke-opacity", "stroke-width")
#: Largest exact assignment problem solved per terminal; larger groups match greedily.
_ASSIGN_LIMIT = 1500
#: Instances nearest each element whose costs are measured before the whole matrix is.
_NEAREST = 8
#: Style lengths that a ``scaled`` terminal's instances scale with their turtle.
_LENGTHS = ("stroke-width", "stroke-dasharray", "stroke-dashoffset")
#: Relative agreement of stroke widths over scales for a terminal to count as ``scaled``
#: (styles carry six digits; poses are fitted).
_SCALED_TOL = 2e-3


def match_instances(
    drawing_names: list[str],
    symbol: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    element_names: list[str],
    ea,
    eb,
) -> np.ndarray | None:
    """Return, for every derived instance, the index of the input element it reproduces.

    Instances and elements are matched terminal by terminal (by name) on their poses; None
    when the counts of some terminal differ (the grammar does not reproduce the input).
    """
    out = np.full(symbol.size, -1, np.int64)
    inst_name = np.asarray(drawing_names, dtype=object)[symbol] if symbol.size else np.zeros(0, object)
    el_name = np.asarray(element_names, dtype=object)
    if inst_name.size != el_name.size:
        return None
    scale = max(float(np.ptp(np.concatenate([eb.real, eb.imag]))) if eb.size else 1.0, 1e-12)
    for name in set(element_names):
        mine = np.flatnonzero(el_name == name)
        theirs = np.flatnonzero(inst_name == name)
        if mine.size != theirs.size:
            return None
        if mine.size <= _ASSIGN_LIMIT:
            found = _clear_nearest(eb[mine], ea[mine], b[theirs], a[theirs], scale)
            if found is None:
                cost = np.abs(eb[mine][:, None] - b[theirs][None, :]) + scale * 1e-3 * np.abs(
                    ea[mine][:, None] - a[theirs][None, :]
                )
                found = _assignment(cost, scale)
            rows, cols = found
            out[theirs[cols]] = mine[rows]
        else:
            out[theirs] = _greedy(eb[mine], b[theirs], mine)
    return out


def _assignment(cost: np.ndarray, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """The one-to-one matching of least total ``cost`` (rows, columns), as ``linear_sum_assignment`` gives it.

    When every row's cheapest column is a different column, each clearly (by ``1e-9·scale``)
    cheaper than the row's others, that matching is the only optimum and is taken as it is:
    a derivation that reproduces its drawing always matches so, and importing scipy's
    optimiser and solving took 0.15-0.45 s of a 1,200-leaf grid's whole run.
    """
    n = cost.shape[0]
    if n == 1:
        return np.zeros(1, np.intp), np.zeros(1, np.intp)
    if n >= 2:
        two = np.partition(cost, 1, axis=1)
        cols = np.argmin(cost, axis=1)
        if np.all(two[:, 1] > two[:, 0] + 1e-9 * scale) and np.unique(cols).size == n:
            return np.arange(n), cols
    from scipy.optimize import linear_sum_assignment

    return linear_sum_assignment(cost)


def _clear_nearest(
    eb: np.ndarray, ea: np.ndarray, b: np.ndarray, a: np.ndarray, scale: float
) -> tuple[np.ndarray, np.ndarray] | None:
    """What :func:`_assignment` finds without the whole cost matrix, when its first case holds.

    The cost of a pair is at least the distance of its places, so the :data:`_NEAREST`
    instances nearest every element (a k-d tree) hold the element's two cheapest ones
    whenever the farthest of them is farther than the second cheapest.  When that holds for
    every element and each has one clearly cheapest instance, a different one for each, that
    is the only optimum (the costs are the dense matrix's own, to the bit); otherwise None.
    The matrix of a 1,200-leaf grid took 30 ms of every weight change.
    """
    n = eb.size
    if n <= 2 * _NEAREST:
        return None
    from scipy.spatial import cKDTree

    dist, near = cKDTree(np.column_stack([b.real, b.imag])).query(
        np.column_stack([eb.real, eb.imag]), k=_NEAREST
    )
    cost = np.abs(eb[:, None] - b[near]) + scale * 1e-3 * np.abs(ea[:, None] - a[near])
    two = np.partition(cost, 1, axis=1)
    cols = near[np.arange(n), np.argmin(cost, axis=1)]
    clear = two[:, 1] > two[:, 0] + 1e-9 * scale
    outside = dist[:, -1] > two[:, 1] + 1e-9 * scale  # every other instance costs more still
    if clear.all() and outside.all() and np.unique(cols).size == n:
        return np.arange(n), cols
    return None


def _greedy(target: np.ndarray, found: np.ndarray, ids: np.ndarray) -> np.ndarray:
    """Match points ``found`` to ``target`` one to one, nearest pairs first (ids of the targets).

    The pairs of every point and its 8 nearest targets are taken in order of distance; the
    loop ends when every point has one (50,052 derived leaves: 0.27-0.57 -> 0.17-0.33 s).
    A vectorised greedy (:func:`lsys_core.hierarchy.flat.greedy_links`) took 0.53-0.70 s.

    When every point has one strictly nearest target, a different one for each (a derivation
    that reproduces its drawing), each point's first pair is its nearest target and nothing
    has taken it: that is the matching, read off two neighbours per point without the loop
    (50,052 derived leaves: 0.14 -> 0.045 s).
    """
    from scipy.spatial import cKDTree

    tree = cKDTree(np.column_stack([target.real, target.imag]))
    points = np.column_stack([found.real, found.imag])
    if target.size >= 2 and found.size:
        dist, near = tree.query(points, k=2)
        if (dist[:, 1] > dist[:, 0]).all() and np.bincount(near[:, 0], minlength=target.size).max() <= 1:
            return ids[near[:, 0]]
    return _greedy_pairs(tree, target.size, points, ids)


def _greedy_pairs(tree, n_targets: int, points: np.ndarray, ids: np.ndarray) -> np.ndarray:
    """:func:`_greedy` by taking the pairs of every point and its 8 nearest targets in order of distance."""
    k = min(8, n_targets)
    dist, near = tree.query(points, k=k)
    n = points.shape[0]
    dist, near = dist.reshape(n, k), near.reshape(n, k)
    rows, cols = np.divmod(np.argsort(dist, axis=None, kind="stable"), k)
    result = np.full(n, -1, np.int64)
    taken = np.zeros(n_targets, bool)
    left = n  # once every point has its target, the rest of the pairs change nothing
    for i, t in zip(rows.tolist(), near[rows, cols].tolist(), strict=True):
        if result[i] < 0 and not taken[t]:
            result[i], taken[t] = t, True
            left -= 1
            if not left:
                break
    rest = np.flatnonzero(result < 0)
    result[rest] = np.flatnonzero(~taken)[: rest.size]
    return ids[result]


def fit_paint(
    g: Grammar,
    element_styles: list[str],
    element_order: np.ndarray,
    match: np.ndarray,
    trace: Trace,
    drawing: Drawing,
) -> Grammar:
    """Return ``g`` with styles and paint order that reproduce the matched elements'.

    Parameters
    ----------
    g : Grammar
        A grammar without paints or tables, whose derivation gave ``trace``.
    element_styles : list of str
        Resolved style of every input element.
    element_order : ndarray
        Paint-order key of every input element (document order).
    match : ndarray of int
        Element index of every derived instance (in the trace's order).
    trace : Trace
        The derivation's trace.
    drawing : Drawing
        The derivation's drawing (same order as the trace).
    """
    styles = np.asarray(element_styles, dtype=object)[match]
    g, styles = _scaled_strokes(g, styles, drawing)
    order = np.asarray(element_order, float)[match]
    edits: dict[tuple[str, int, int], dict] = {}
    g, table = _fit_styles(g, styles, trace, edits)
    g, z_table = _fit_order(g, order, trace, edits)
    g = _apply(g, edits)
    if table is not None:
        g = replace(g, paint=table)
    if z_table is not None:
        g = replace(g, order=z_table)
    return g


def _scaled_strokes(g: Grammar, styles: np.ndarray, drawing: Drawing) -> tuple[Grammar, np.ndarray]:
    """Mark ``scaled`` the terminals whose instances' stroke lengths are proportional to their scale.

    Their instances' styles are rewritten in the terminal's own units (the lengths divided by
    the instance's scale), so that copies drawn with one style through scaling transforms
    share one style again.
    """
    scale = np.abs(np.asarray(drawing.a, complex))
    styles = styles.copy()
    scaled = set()
    base = drawing.base_symbol()  # a stretched instance is one of its terminal's
    for t, term in enumerate(drawing.terminals[: len(g.terminals)]):
        mine = np.flatnonzero(base == t)
        if mine.size < 2 or term.scaled or np.ptp(scale[mine]) <= _SCALED_TOL * scale[mine].max():
            continue
        local = _local_lengths([str(v) for v in styles[mine]], scale[mine])
        if local is not None:
            styles[mine] = local
            scaled.add(term.name)
    if not scaled:
        return g, styles
    terms = tuple(replace(t, scaled=True) if t.name in scaled else t for t in g.terminals)
    return replace(g, terminals=terms), styles


def _local_lengths(styles: list[str], scale: np.ndarray) -> list[str] | None:
    """Return the styles with their lengths divided by ``scale``, if that makes them one style."""
    decls = [css_decls(s) for s in styles]
    if any(d.keys() != decls[0].keys() for d in decls) or "stroke-width" not in decls[0]:
        return None
    rest = [{k: v for k, v in d.items() if k not in _LENGTHS} for d in decls]
    if any(r != rest[0] for r in rest):
        return None
    out = dict(decls[0])
    for key in _LENGTHS:
        if key not in out:
            continue
        try:
            values = np.array([[float(x) for x in re.split(r"[\s,]+", d[key].strip())] for d in decls])
        except ValueError:
            return None  # units, keywords or lists of different lengths
        local = values / scale[:, None]
        mid = np.median(local, axis=0)
        if np.any(np.abs(local - mid) > _SCALED_TOL * np.maximum(np.abs(mid), 1e-12)):
            return None
        out[key] = " ".join(f"{v:.6g}" for v in mid)
    if all(d == decls[0] for d in decls):
        return None  # one style already: canvas units serve
    return [css_text(out)] * len(styles)


def _named(names: dict[str, str], css: str) -> str:
    """Return the name of the named style with declarations ``css`` (made if new)."""
    if css not in names:
        names[css] = f"s{len(names) + 1}"
    return names[css]


def _most_common(styles: list[str]) -> str:
    """The most common of ``styles``, the least of them in string order among equally common ones.

    What ``np.unique(..., return_counts=True)`` and the first largest count give, by counting
    (50,052 instances of one style: 15 -> 3 ms).
    """
    counts = Counter(map(str, styles))
    return min(counts.items(), key=lambda kv: (-kv[1], kv[0]))[0]


def _fit_styles(g: Grammar, styles: np.ndarray, trace: Trace, edits: dict) -> tuple[Grammar, tuple | None]:
    """Choose base styles, occurrence paints and a ``paint:`` table; record paints in ``edits``."""
    n = styles.size
    if n == 0:
        return g, None
    slot_terms = {}
    for s in np.unique(trace.slot).tolist():
        owner, ci, mi = trace.slots[s]
        slot_terms[s] = _module(g, owner, ci, mi).name
    # Base style of each terminal: the most common among its instances (ties: the least, as
    # ``np.unique`` sorts them); the instances grouped by terminal with one stable sort
    index = {t.name: k for k, t in enumerate(g.terminals)}
    term_of_slot = np.full(len(trace.slots), len(g.terminals), np.int64)
    for s, name in slot_terms.items():
        term_of_slot[s] = index.get(name, len(g.terminals))
    term = term_of_slot[trace.slot]
    by_term = np.argsort(term, kind="stable")
    bounds = np.searchsorted(term[by_term], np.arange(len(g.terminals) + 1))
    base = {}
    for k, t in enumerate(g.terminals):
        if bounds[k + 1] > bounds[k]:
            base[t.name] = _most_common(styles[by_term[bounds[k] : bounds[k + 1]]].tolist())
    g = replace(g, terminals=tuple(replace(t, style=base.get(t.name, t.style)) for t in g.terminals))
    names: dict[str, str] = {}
    table: list[str | None] = [None] * n
    need_table = False
    for s, term in slot_terms.items():
        sel = np.flatnonzero(trace.slot == s)
        own = base.get(term, "")
        distinct = list(dict.fromkeys(map(str, styles[sel].tolist())))
        if len(distinct) == 1:
            if distinct[0] != own:
                edits.setdefault(trace.slots[s], {})["style"] = _named(names, distinct[0])
            continue
        fitted = _linear_props(styles[sel].tolist(), trace.m[sel])
        if fitted is not None:
            common, props = fitted
            entry = edits.setdefault(trace.slots[s], {})
            if common != own:
                entry["style"] = _named(names, common)
            entry["props"] = props
            continue
        need_table = True
        for i in sel.tolist():
            if styles[i] != own:
                table[int(trace.position[i])] = _named(names, styles[i])
    named = tuple(NamedStyle(name, css) for css, name in names.items())
    g = replace(g, styles=named)
    if not need_table:
        return g, None
    while table and table[-1] is None:
        table.pop()
    return g, tuple(table)


def _linear_props(styles: list[str], m: np.ndarray) -> tuple[str, list[tuple[str, Linear]]] | None:
    """Return the shared declarations and the numeric ones linear in ``m``, or None."""
    decls = [css_decls(s) for s in styles]
    keys = set(decls[0])
    if any(set(d) != keys for d in decls):
        return None
    varying = [k for k in keys if len({d[k] for d in decls}) > 1]
    if not varying or any(k not in _NUMERIC for k in varying):
        return None
    props = []
    mm = m.astype(float)
    if np.ptp(mm) == 0:
        return None
    for k in sorted(varying, key=_NUMERIC.index):
        try:
            v = np.array([float(d[k]) for d in decls])
        except ValueError:
            return None
        cd, c0 = np.polyfit(mm, v, 1)
        fit = c0 + cd * mm
        if np.abs(fit - v).max() > _written_precision([d[k] for d in decls], v):
            return None
        props.append((k, Linear(_round(c0), _round(cd))))
    common = dict(decls[0])
    for k in varying:
        common.pop(k)
    return css_text(common), props


def _written_precision(texts: list[str], values: np.ndarray) -> float:
    """How far numbers written as ``texts`` may be from the values they round.

    Half a unit of the last decimal the most precise of them writes (``.14``, ``.29``, ``.43``:
    0.005, so sevenths written with two decimals are one progression), and at least six
    significant digits' worth.
    """
    decimals = [len(t.split(".", 1)[1]) for t in texts if "." in t and t.replace(".", "", 1).isdigit()]
    written = 0.5 * 10.0 ** -max(decimals) if decimals else 0.0
    return max(written * (1 + 1e-9), 1e-6 * max(1.0, float(np.abs(values).max())) + 5e-7)


def _round(x: float) -> float:
    """Round to 9 significant digits (a fit of 6-digit style numbers)."""
    return float(f"{x:.9g}") + 0.0


def _fit_order(g: Grammar, order: np.ndarray, trace: Trace, edits: dict) -> tuple[Grammar, tuple | None]:
    """Give occurrences ``z`` values, or an ``order:`` table, so instances paint in document order."""
    n = order.size
    if n < 2 or np.all(np.diff(order) >= 0):  # the derivation already paints in document order
        return g, None
    # Per occurrence: document order linear in the counter?
    zs = np.zeros(n)
    fits: dict[int, tuple[float, float]] | None = {}
    for s in np.unique(trace.slot).tolist():
        sel = np.flatnonzero(trace.slot == s)
        mm = trace.m[sel].astype(float)
        target = order[sel]
        if sel.size == 1 or np.ptp(mm) == 0:
            if np.ptp(target) > 0:
                fits = None
                break
            c0, cd = float(target[0]), 0.0
        else:
            if np.unique(mm).size != mm.size:
                fits = None
                break
            cd, c0 = np.polyfit(mm, target, 1)
            c0, cd = _round(c0), _round(cd)
        zs[sel] = c0 + cd * mm
        assert fits is not None
        fits[s] = (c0, cd)
    if fits is not None:
        by_z = np.lexsort((trace.position, zs))
        if np.all(np.diff(order[by_z]) >= 0):
            for s, (c0, cd) in fits.items():
                edits.setdefault(trace.slots[s], {})["z"] = Linear(c0, cd)
            return g, None
    table = np.zeros(n)
    table[trace.position] = order
    return g, tuple(float(v) for v in table)


def _module(g: Grammar, owner: str, ci: int, mi: int) -> Symbol:
    """Return the terminal occurrence at ``(owner, case, module index)``."""
    rule = g.rule(owner)
    body = g.axiom if owner == "axiom" or rule is None else rule.cases[ci].body
    mod = body[mi]
    assert isinstance(mod, Symbol)
    return mod


def _apply(g: Grammar, edits: dict) -> Grammar:
    """Write the recorded paints (style, properties) and ``z`` values into the bodies.

    A paint-order value is the occurrence's paint property ``z`` (``A{z: 4 + 2*m}``).
    """
    if not edits:
        return g

    def body(owner: str, ci: int, mods: tuple[Module, ...]) -> tuple[Module, ...]:
        out = list(mods)
        for (o, c, mi), e in edits.items():
            if o != owner or c != ci:
                continue
            mod = out[mi]
            props = list(e.get("props", ()))
            if "z" in e and (e["z"].c0 != 0 or e["z"].cd != 0):
                props.append(("z", e["z"]))
            if e.get("style") is None and not props:
                continue
            out[mi] = replace(mod, paint=Paint(e.get("style"), tuple(props)))
        return tuple(out)

    rules = tuple(
        replace(r, cases=tuple(replace(c, body=body(r.name, ci, c.body)) for ci, c in enumerate(r.cases)))
        for r in g.rules
    )
    return replace(g, rules=rules, axiom=body("axiom", 0, g.axiom))
