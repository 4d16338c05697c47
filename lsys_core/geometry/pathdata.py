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

__all__ = [
    "ARC",
    "CLOSE",
    "CUBIC",
    "LINE",
    "MAX_NUMBER",
    "MOVE",
    "QUAD",
    "PathTable",
    "parse_path",
    "parse_paths",
]

MOVE, LINE, QUAD, CUBIC, ARC, CLOSE = range(6)
#: Numbers beyond this magnitude make the whole path unreadable (they mean broken data).
MAX_NUMBER = 1e15

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
    """Path data (of one or several paths) as one row per segment, in absolute coordinates.

    ``op`` is the kind of each row (:data:`MOVE`, :data:`LINE`, :data:`QUAD`, :data:`CUBIC`,
    :data:`ARC`, :data:`CLOSE`); ``pts`` its control points ``p0 c1 c2 p3`` (``p0 p0 p3 p3`` for
    lines, moves, closes and arcs, ``p0 q q p3`` for quadratics); ``arc`` holds ``rx ry phi
    large sweep`` for each arc row, in row order; ``path`` the path of each row (rows of one
    path are consecutive).  ``errors`` names the first problem of each path (None: all of its
    data was read).
    """

    op: np.ndarray
    pts: np.ndarray
    arc: np.ndarray
    path: np.ndarray
    errors: tuple[str | None, ...]

    @property
    def error(self) -> str | None:
        """The first problem of the first path (for a table of one path)."""
        return self.errors[0] if self.errors else None


def _empty(errors: tuple[str | None, ...]) -> PathTable:
    z = np.zeros(0, dtype=np.intp)
    return PathTable(np.zeros(0, np.int8), np.zeros((0, 4), complex), np.zeros((0, 5)), z, errors)


def parse_path(d: str) -> PathTable:
    """Parse the path data of one path (see the module docstring)."""
    return parse_paths([d])


def parse_paths(ds: list[str], max_numbers: int | None = None) -> PathTable:
    """Parse the path data of several paths at once (one lexing pass, one resolution pass).

    Each path is read on its own, as if alone: its first move is absolute and an error in it
    ends only that path.  ``max_numbers`` bounds the numbers read, all paths together
    (:class:`~lsys_core.errors.LimitError` beyond).
    """
    n_paths = len(ds)
    messages: list[str | None] = [None] * n_paths
    letters, first, arity, groups, let_path, values = _commands(ds, max_numbers, messages)
    return _execute(letters, first, arity, groups, let_path, values, n_paths, tuple(messages))


def _commands(ds: list[str], max_numbers: int | None, messages: list[str | None]) -> tuple:
    """Lex the paths and keep each one's commands up to its first error (noted in ``messages``).

    Returns ``(letters, first, arity, groups, let_path, values)`` for :func:`_execute`: the lexing
    arrays die with this call (for 10^6 commands they are about 100 MiB beside these).
    """
    n_paths = len(ds)
    lens = np.fromiter((len(d) for d in ds), dtype=np.int64, count=n_paths)
    offs = np.cumsum(lens + 1) - (lens + 1)  # each path's first byte in the joined text
    ends = offs + lens
    joined = "\n".join(ds)
    lexed = lex(joined, max_numbers=max_numbers)
    values, starts, letters, lpos = lexed.values, lexed.starts, lexed.letters, lexed.letter_pos
    lex_errors = lexed.errors
    del lexed
    # Each path is read up to its first error.
    cut = ends.copy()
    if lex_errors.size:
        err_path = np.searchsorted(offs, lex_errors, side="right") - 1
        first_err, where = np.unique(err_path, return_index=True)
        cut[first_err] = lex_errors[where]
        for p, e in zip(first_err.tolist(), lex_errors[where].tolist(), strict=True):
            messages[p] = f"unexpected character at offset {e - int(offs[p])}"
    tok_path = np.searchsorted(offs, starts, side="right") - 1
    let_path = np.searchsorted(offs, lpos, side="right") - 1
    # A path with a number beyond MAX_NUMBER is not read at all (its sums would overflow).
    huge = ~(np.abs(values) <= MAX_NUMBER)
    if huge.any():
        for p in np.unique(tok_path[huge]).tolist():
            cut[p] = offs[p]
            messages[p] = f"a number beyond {MAX_NUMBER:.0e}"
    keep_tok = starts < cut[tok_path]
    keep_let = lpos < cut[let_path]
    # A path must begin with a move: its first token is an M or m.
    first_let = np.full(n_paths, np.iinfo(np.int64).max)
    np.minimum.at(first_let, let_path[keep_let], lpos[keep_let])
    first_num = np.full(n_paths, np.iinfo(np.int64).max)
    np.minimum.at(first_num, tok_path[keep_tok], starts[keep_tok])
    letter_at_first = np.zeros(n_paths, dtype=np.uint8)
    has_let = first_let < np.iinfo(np.int64).max
    if keep_let.any():
        first_idx = np.searchsorted(lpos, first_let[has_let])
        letter_at_first[has_let] = letters[first_idx]
    good_start = has_let & (first_let < first_num) & np.isin(letter_at_first, (ord("M"), ord("m")))
    for p in np.flatnonzero(~good_start & (lens > 0)).tolist():
        if messages[p] is None or has_let[p]:
            messages[p] = "path data must begin with a move command (M or m)"
    keep_tok &= good_start[tok_path]
    keep_let &= good_start[let_path]
    del tok_path
    if not keep_tok.all():  # (all kept: no copies)
        values, starts = values[keep_tok], starts[keep_tok]
    if not keep_let.all():
        letters, lpos, let_path = letters[keep_let], lpos[keep_let], let_path[keep_let]
    del keep_tok, keep_let
    first = np.searchsorted(starts, lpos)  # first number after each command letter
    del starts
    count = np.diff(first, append=values.size)
    arity = _ARITY[letters]
    values, first, count = _fix_arc_flags(
        joined, letters, lpos, np.minimum(cut, ends)[let_path], values, first, count
    )
    div = np.maximum(arity, 1)
    ok = np.where(arity == 0, count == 0, (count > 0) & (count % div == 0))
    groups = np.where(arity == 0, 1, count // div)
    bad = np.flatnonzero(~ok)
    if bad.size:
        # The first bad command of a path keeps its complete groups; the path ends there.
        bad_paths, where = np.unique(let_path[bad], return_index=True)
        stop_at = np.full(n_paths, np.iinfo(np.int64).max)
        stop_at[bad_paths] = bad[where]
        keep = np.arange(letters.size) <= stop_at[let_path]
        for p, c in zip(bad_paths.tolist(), bad[where].tolist(), strict=True):
            if messages[p] is None:
                what = "numbers after Z" if arity[c] == 0 else "incomplete arguments"
                ordinal = c - int(np.searchsorted(let_path, p))
                messages[p] = f"{what} for command {chr(letters[c])} (number {ordinal + 1})"
        letters, first, arity, groups, let_path = (x[keep] for x in (letters, first, arity, groups, let_path))
    return letters, first, arity, groups, let_path, values


def _fix_arc_flags(text, letters, lpos, limit, values, first, count):
    """Re-read arc commands whose flags are written without separators (``0 011 1``).

    ``limit`` is, per command, where its path's readable text ends.
    """
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
    raw = text.encode("ascii", "replace")
    extra: list[np.ndarray] = []
    first = first.copy()
    count = count.copy()
    offset = values.size
    for c in np.flatnonzero(suspect).tolist():
        end = int(lpos[c + 1]) if c + 1 < lpos.size else len(raw)
        nums = _arc_args(raw[int(lpos[c]) + 1 : min(end, int(limit[c]))])
        extra.append(nums)
        first[c], count[c] = offset, nums.size
        offset += nums.size
    if extra:
        values = np.concatenate([values, *extra])
    return values, first, count


def _scan_number(text: bytes, i: int) -> int:
    """Return the end of the number starting at ``text[i]`` (``i`` itself if there is none)."""
    n = len(text)
    j = i
    if j < n and text[j] in b"+-":
        j += 1
    digits = 0
    while j < n and 48 <= text[j] <= 57:
        j, digits = j + 1, digits + 1
    if j < n and text[j] == 46:  # "."
        j += 1
        while j < n and 48 <= text[j] <= 57:
            j, digits = j + 1, digits + 1
    if digits == 0:
        return i
    if j < n and text[j] in b"eE":
        k = j + 1
        if k < n and text[k] in b"+-":
            k += 1
        if k < n and 48 <= text[k] <= 57:
            while k < n and 48 <= text[k] <= 57:
                k += 1
            j = k
    return j


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
        j = _scan_number(text, i)
        if j == i:
            break
        out.append(float(text[i:j]))
        i = j
    if len(out) % 7:
        out = [*out[: len(out) - len(out) % 7], np.nan]  # incomplete group: marks the error
    return np.asarray(out, dtype=float)


def _reset_sum(values: np.ndarray, reset: np.ndarray) -> np.ndarray:
    """Prefix sums that restart at every ``reset`` row (where the row's own value is the start)."""
    cs = np.where(reset, 0, values)
    np.cumsum(cs, out=cs)
    last = np.arange(values.size)
    last[~reset] = 0
    np.maximum.accumulate(last, out=last)
    # In place: the same operations as ``values[last] * reset[last] + cs - cs[last]``.
    out = values[last]
    out *= reset[last]
    out += cs
    out -= cs[last]
    return out


def _execute(letters, first, arity, groups, let_path, values, n_paths, errors) -> PathTable:
    """Expand commands into rows and resolve them to absolute coordinates."""
    n = int(groups.sum())
    if n == 0:
        return _empty(errors)
    cmd = np.repeat(np.arange(letters.size), groups)
    g = np.arange(n) - np.repeat(np.cumsum(groups) - groups, groups)  # group index within command
    base_idx = first[cmd] + g * arity[cmd]
    path = let_path[cmd]
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
    path_first = np.ones(n, dtype=bool)
    path_first[1:] = path[1:] != path[:-1]
    rel[path_first] = False  # the leading "m" of a path is absolute
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
    return PathTable(op, pts, arc, path, errors)


def _group_offsets(is_move, close, setc, e):
    """Offsets within subpath groups: per row, ``(offset, known)``; known rows are absolute."""
    reset = is_move | close | setc
    off = _reset_sum(np.where(reset, np.where(setc & ~is_move, e, 0.0), e), reset)
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
        start += off
        out.append(np.where(known, off, start))
        del off, known, start
    return _complex(out.pop(0), out.pop())


def _complex(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``x + 1j * y`` (the same values, signs of zero included) without complex temporaries."""
    z = np.empty(x.size, dtype=complex)
    re = y * 0.0  # the product 1j * y has the real part 0 * y - 0 and the imaginary part 0 + y
    re -= 0.0
    re += x
    z.real = re
    del re
    np.add(y, 0.0, out=z.imag)
    return z


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
