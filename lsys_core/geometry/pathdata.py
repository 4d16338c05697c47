"""SVG path data to a table of absolute segments, vectorised (memory proportional to the commands).

:func:`parse_path` lexes the data with :mod:`lsys_core.geometry.numbers`, expands implicit command
repetition, and resolves relative coordinates, ``H``/``V``, smooth curves (``S``/``T``) and
closing (``Z``) with prefix sums instead of a loop over commands: a coordinate is either set
(absolute command) or moved (relative command), so the current point is a prefix sum that restarts
at every absolute command; a subpath's start is a second such sum over the subpaths.  Only arcs
whose flags are written without separators (``a1 1 0 011 1``) are re-read one command at a time.

As SVG asks, data with an error is drawn up to the last complete command before it; the table
says where and why it stopped (:attr:`PathTable.error`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from lsys_core.geometry.numbers import lex

__all__ = ["ARC", "CLOSE", "CUBIC", "LINE", "MOVE", "QUAD", "PathTable", "parse_path"]

MOVE, LINE, QUAD, CUBIC, ARC, CLOSE = range(6)

_ARITY = np.zeros(256, dtype=np.intp)
_OP = np.full(256, -1, dtype=np.int8)
for _ch, _k, _op in (
    ("M", 2, MOVE),
    ("Z", 0, CLOSE),
    ("L", 2, LINE),
    ("H", 1, LINE),
    ("V", 1, LINE),
    ("C", 6, CUBIC),
    ("S", 4, CUBIC),
    ("Q", 4, QUAD),
    ("T", 2, QUAD),
    ("A", 7, ARC),
):
    for _c in (_ch, _ch.lower()):
        _ARITY[ord(_c)] = _k
        _OP[ord(_c)] = _op


class PathTable(NamedTuple):
    """Path data as one row per segment, in absolute coordinates.

    ``op`` is the kind of each row (:data:`MOVE`, :data:`LINE`, :data:`QUAD`, :data:`CUBIC`,
    :data:`ARC`, :data:`CLOSE`); ``pts`` its control points ``p0 c1 c2 p3`` (``p0 p0 p3 p3`` for
    lines, moves, closes and arcs, ``p0 q q p3`` for quadratics); ``arc`` holds ``rx ry phi
    large sweep`` for each arc row, in row order.  ``error`` names the first problem (None: all
    of the data was read).
    """

    op: np.ndarray
    pts: np.ndarray
    arc: np.ndarray
    error: str | None


def _empty(error: str | None) -> PathTable:
    return PathTable(np.zeros(0, np.int8), np.zeros((0, 4), complex), np.zeros((0, 5)), error)


def parse_path(d: str) -> PathTable:
    """Parse SVG path data (see the module docstring)."""
    lexed = lex(d)
    letters, lpos, values, starts = lexed.letters, lexed.letter_pos, lexed.values, lexed.starts
    error = None if lexed.error < 0 else f"unexpected character at offset {lexed.error}"
    if letters.size == 0:
        return _empty("no commands" if values.size or error else error)
    if (values.size and starts[0] < lpos[0]) or letters[0] not in (ord("M"), ord("m")):
        return _empty("path data must begin with a move command (M or m)")
    first = np.searchsorted(starts, lpos)  # first number after each command letter
    count = np.diff(first, append=values.size)
    del starts
    arity = _ARITY[letters]
    values, first, count = _fix_arc_flags(d, letters, lpos, values, first, count, arity)
    div = np.maximum(arity, 1)
    ok = np.where(arity == 0, count == 0, (count > 0) & (count % div == 0))
    groups = np.where(arity == 0, 1, count // div)
    bad = np.flatnonzero(~ok)
    if bad.size:
        stop = int(bad[0])
        what = "numbers after Z" if arity[stop] == 0 else "incomplete arguments"
        error = error or f"{what} for command {chr(letters[stop])} (number {stop + 1})"
        # Complete argument groups before the error still count (implicit repetition).
        groups = groups[: stop + 1]
        letters, first, arity = letters[: stop + 1], first[: stop + 1], arity[: stop + 1]
    return _execute(letters, first, arity, groups, values, error)


def _fix_arc_flags(d, letters, lpos, values, first, count, arity):
    """Re-read arc commands whose flags are written without separators (``0 011 1``)."""
    is_arc = (letters == ord("A")) | (letters == ord("a"))
    if not is_arc.any():
        return values, first, count
    arcs = np.flatnonzero(is_arc)
    # Arguments of arc commands: their ordinal within the command; flags must be exactly 0 or 1.
    tok_cmd = np.repeat(arcs, count[arcs])
    ordinal = np.arange(tok_cmd.size) - np.repeat(np.cumsum(count[arcs]) - count[arcs], count[arcs])
    tok = np.repeat(first[arcs], count[arcs]) + ordinal
    flag = (ordinal % 7 == 3) | (ordinal % 7 == 4)
    bad_flag = flag & (values[tok] != 0.0) & (values[tok] != 1.0)
    suspect = np.zeros(letters.size, dtype=bool)
    suspect[tok_cmd[bad_flag]] = True
    suspect[arcs[(count[arcs] % 7 != 0) | (count[arcs] == 0)]] = True
    if not suspect.any():
        return values, first, count
    raw = d.encode("ascii", "replace")
    extra: list[np.ndarray] = []
    first = first.copy()
    count = count.copy()
    offset = values.size
    for c in np.flatnonzero(suspect).tolist():
        end = int(lpos[c + 1]) if c + 1 < lpos.size else len(raw)
        nums = _arc_args(raw[int(lpos[c]) + 1 : end])
        extra.append(nums)
        first[c], count[c] = offset, nums.size
        offset += nums.size
    if extra:
        values = np.concatenate([values, *extra])
    return values, first, count


def _arc_args(text: bytes) -> np.ndarray:
    """Read the arguments of one arc command, flags being single characters ``0`` or ``1``."""
    out: list[float] = []
    i, n = 0, len(text)
    while True:
        while i < n and text[i] in b" \t\r\n\f,":
            i += 1
        if i >= n:
            break
        if len(out) % 7 in (3, 4):
            if text[i] not in b"01":
                break
            out.append(float(text[i] - 48))
            i += 1
            continue
        j = i + 1
        while j < n and text[j] not in b" \t\r\n\f,":
            j += 1
        lexed = lex(text[i:j], letters=False)
        if lexed.values.size == 0:
            break
        out.append(float(lexed.values[0]))
        i += int(lexed.starts[1]) if lexed.starts.size > 1 else j - i
    if len(out) % 7:
        out = [*out[: len(out) - len(out) % 7], np.nan]  # incomplete group: marks the error
    return np.asarray(out, dtype=float)


def _reset_sum(values: np.ndarray, reset: np.ndarray) -> np.ndarray:
    """Prefix sums that restart at every ``reset`` row (where the row's own value is the start)."""
    cs = np.cumsum(np.where(reset, 0, values))
    last = np.maximum.accumulate(np.where(reset, np.arange(values.size), 0))
    return values[last] * reset[last] + cs - cs[last]


def _execute(letters, first, arity, groups, values, error) -> PathTable:
    """Expand commands into rows and resolve them to absolute coordinates."""
    n = int(groups.sum())
    if n == 0:
        return _empty(error)
    cmd = np.repeat(np.arange(letters.size), groups)
    g = np.arange(n) - np.repeat(np.cumsum(groups) - groups, groups)  # group index within command
    k = arity[cmd]
    base_idx = first[cmd] + g * k
    del cmd
    letter = np.repeat(letters, groups)
    rel = letter >= ord("a")
    up = np.where(rel, letter - 32, letter).astype(np.uint8)
    del letter

    def arg(j: int, rows: np.ndarray) -> np.ndarray:
        return values[base_idx[rows] + j]

    op = _OP[up]
    is_move = (up == ord("M")) & (g == 0)
    op[(up == ord("M")) & (g > 0)] = LINE  # implicit lines after a move
    del g
    rel[:1] = False  # a leading "m" is absolute
    # The end point of every row: set (absolute) or moved (relative) in x and in y.
    ex = np.zeros(n)
    ey = np.zeros(n)
    for letters_, jx in ((b"MLT", 0), (b"C", 4), (b"SQ", 2), (b"A", 5)):
        rows = np.flatnonzero(np.isin(up, np.frombuffer(letters_, np.uint8)))
        ex[rows], ey[rows] = arg(jx, rows), arg(jx + 1, rows)
    h = np.flatnonzero(up == ord("H"))
    ex[h] = arg(0, h)
    v = np.flatnonzero(up == ord("V"))
    ey[v] = arg(0, v)
    close = up == ord("Z")
    setx = ~rel & ~close
    sety = setx.copy()
    sety[h] = False  # H moves y by 0
    setx[v] = False
    cur = _positions(is_move, close, setx, sety, ex, ey)
    del ex, ey, setx, sety
    pts = np.empty((n, 4), dtype=complex)
    pts[0, 0] = cur[0]
    pts[1:, 0] = cur[:-1]
    pts[:, 1] = pts[:, 0]
    pts[:, 2] = cur
    pts[:, 3] = cur
    del cur
    p0 = pts[:, 0]

    def point(j: int, rows: np.ndarray) -> np.ndarray:
        return np.where(rel[rows], p0[rows], 0) + arg(j, rows) + 1j * arg(j + 1, rows)

    c = np.flatnonzero(up == ord("C"))
    pts[c, 1], pts[c, 2] = point(0, c), point(2, c)
    s = np.flatnonzero(up == ord("S"))
    pts[s, 2] = point(0, s)
    prev_cubic = np.zeros(n, dtype=bool)
    prev_cubic[1:] = (op[:-1] == CUBIC) & ~is_move[1:]
    pts[s, 1] = np.where(prev_cubic[s], 2 * p0[s] - pts[np.maximum(s - 1, 0), 2], p0[s])
    q = np.flatnonzero(up == ord("Q"))
    pts[q, 1] = pts[q, 2] = point(0, q)
    t = up == ord("T")
    if t.any():
        qc = _smooth_quads(t, op, p0, pts, is_move)
        pts[t, 1] = pts[t, 2] = qc[t]
    a = np.flatnonzero(up == ord("A"))
    arc = np.stack([arg(j, a) for j in range(5)], axis=1) if a.size else np.zeros((0, 5))
    return PathTable(op, pts, arc, error)


def _group_offsets(is_move, close, setc, e):
    """Offsets within subpath groups: per row, ``(offset, known)``; known rows are absolute."""
    reset = is_move | close | setc
    val = np.where(setc & ~is_move, e, 0.0)
    off = _reset_sum(np.where(reset, val, e), reset)
    anchor = np.maximum.accumulate(np.where(reset, np.arange(e.size), 0))
    known = setc[anchor] & ~is_move[anchor]
    return off, known


def _start_chain(mv, setc, e, off, known) -> np.ndarray:
    """Solve ``s[k] = A`` (absolute move) or ``s[k] = end[k-1] + d`` along the moves.

    ``end[k-1]`` is known (the previous group ends anchored to an absolute command) or
    ``s[k-1]`` plus an offset, so the starts are one more prefix sum with restarts.
    """
    k = mv.size
    w = np.empty(k)
    reset = np.empty(k, dtype=bool)
    w[0], reset[0] = e[mv[0]], True
    if k > 1:
        prev_end = mv[1:] - 1
        abs_move = setc[mv[1:]]
        reset[1:] = abs_move | known[prev_end]
        w[1:] = np.where(abs_move, e[mv[1:]], off[prev_end] + e[mv[1:]])
    return _reset_sum(w, reset)


def _positions(is_move, close, setx, sety, ex, ey) -> np.ndarray:
    """Return the current point after every row."""
    grp = np.cumsum(is_move) - 1
    mv = np.flatnonzero(is_move)
    out = []
    for setc, e in ((setx, ex), (sety, ey)):
        off, known = _group_offsets(is_move, close, setc, e)
        start = _start_chain(mv, setc, e, off, known)[grp]
        out.append(np.where(known, off, start + off))
    return out[0] + 1j * out[1]


def _smooth_quads(t, op, p0, pts, is_move) -> np.ndarray:
    """Control points of ``T`` rows: reflections chained along runs (an alternating prefix sum)."""
    n = t.size
    q_own = np.where(op == QUAD, pts[:, 1], pts[:, 3])  # a non-T row's "previous control"
    sign = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)
    prev_is_q = np.zeros(n, dtype=bool)
    prev_is_q[1:] = (op[:-1] == QUAD) & ~is_move[1:]
    # For a T row whose predecessor is no quadratic, the reflected point is p0 itself.
    reset = ~t | (t & ~prev_is_q)
    base_val = np.where(t, sign * p0, sign * q_own)  # T start: u = (-1)^i * p0
    step = np.where(t, 2 * sign * p0, 0)
    u = _reset_sum(np.where(reset, base_val, step), reset)
    return sign * u
