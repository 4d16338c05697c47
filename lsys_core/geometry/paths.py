"""Path geometry as arrays of cubic Bézier segments, and SVG path data in and out.

Every shape is kept as ``cubics``, a ``(k, 4)`` complex array of control points
``p0, c1, c2, p3`` per segment, with ``subpaths`` (``(k,)`` int: the subpath of
each segment, numbered from 0) and ``closed`` (one bool per subpath).  Lines
become cubics with control points at 1/3 and 2/3, quadratics are degree-elevated
exactly and arcs are approximated by cubics (error far below 1e-6 of the radius).
A closed subpath ends with an explicit segment back to its start (unless it
already ends there), so the segments alone describe the outline.
"""

from __future__ import annotations

import re
from typing import NamedTuple

import numpy as np

from lsys_core.errors import SvgError

__all__ = [
    "RawPath",
    "assemble",
    "cubics_from_d",
    "cubics_from_path",
    "d_from_cubics",
    "raw_from_d",
    "raw_from_segments",
]

#: Segment kinds collected while walking a path (converted to cubics at the end).
_LINE, _QUAD, _CUBIC = 0, 1, 2

#: Relative distance below which a closing segment is rounding noise.
_CLOSE_TOL = 1e-10

#: Largest coordinate magnitude accepted anywhere (import, terminal path data): beyond it, float
#: arithmetic on poses loses all precision.
MAX_COORD = 1e12

#: Default significant digits of numbers written into path data (relative error <= 5e-9).
DEFAULT_PRECISION = 9
#: Exceptions svgelements raises on values it cannot handle (shared with the importer).
SVGELEMENTS_ERRORS = (
    ValueError,
    TypeError,
    IndexError,
    KeyError,
    AttributeError,
    ZeroDivisionError,
    OverflowError,
)


class RawPath(NamedTuple):
    """Segments collected from path data before conversion to arrays.

    ``pts`` holds one 4-tuple of complex per segment: ``p0 c1 c2 p3`` for cubics,
    ``p0 q q p3`` for quadratics and ``p0 p0 p3 p3`` for lines (``kinds`` says which);
    ``subs`` the subpath of each segment and ``closed`` one flag per subpath.
    """

    kinds: list[int]
    pts: list[tuple[complex, complex, complex, complex]]
    subs: list[int]
    closed: list[bool]


def _empty() -> tuple[np.ndarray, np.ndarray, tuple[bool, ...]]:
    return np.zeros((0, 4), dtype=complex), np.zeros(0, dtype=np.intp), ()


def _close(raw: RawPath, cur: complex, start: complex) -> None:
    """Close the current subpath: add a line back to ``start`` unless it ends there."""
    if abs(cur - start) > _CLOSE_TOL * max(abs(cur), abs(start)):
        raw.kinds.append(_LINE)
        raw.pts.append((cur, cur, start, start))
        raw.subs.append(len(raw.closed) - 1)
    elif cur != start:  # rounding noise (e.g. after arcs): end exactly at the start
        last = raw.pts[-1]
        raw.pts[-1] = (last[0], last[1], last[2], start)
    raw.closed[-1] = True


def raw_from_segments(path) -> RawPath:
    """Collect the segments of an svgelements path (or iterable of its segments).

    Zero-length segments and subpaths without segments are dropped; arcs are
    converted to cubics (a zero-radius arc to a line).
    """
    from svgelements import Arc, Close, CubicBezier, Move, QuadraticBezier

    raw = RawPath([], [], [], [])
    kinds, pts, subs, closed = raw
    start = 0j  # start point of the current subpath
    pending = True  # a new subpath begins with the next drawn segment
    for seg in path:
        kind = type(seg)
        if kind is Move:
            end = seg.end
            start = complex(end.x, end.y)
            pending = True
            continue
        if seg.start is None or seg.end is None:
            continue
        p0 = complex(seg.start.x, seg.start.y)
        p3 = complex(seg.end.x, seg.end.y)
        if kind is Close:
            if not pending:
                _close(raw, p0, start)
            pending = True  # drawing after Z starts a new subpath at the same point
            continue
        if kind is CubicBezier:
            c1, c2 = seg.control1, seg.control2
            row = (p0, complex(c1.x, c1.y), complex(c2.x, c2.y), p3)
            code = _CUBIC
        elif kind is QuadraticBezier:
            c = complex(seg.control.x, seg.control.y)
            row = (p0, c, c, p3)
            code = _QUAD
        elif kind is Arc:
            curves = list(seg.as_cubic_curves()) if seg.rx and seg.ry else []
            if curves:
                if pending:
                    closed.append(False)
                    pending = False
                    start = p0
                for cb in curves:
                    kinds.append(_CUBIC)
                    pts.append(
                        (
                            complex(cb.start.x, cb.start.y),
                            complex(cb.control1.x, cb.control1.y),
                            complex(cb.control2.x, cb.control2.y),
                            complex(cb.end.x, cb.end.y),
                        )
                    )
                    subs.append(len(closed) - 1)
                continue
            row = (p0, p0, p3, p3)  # zero radius: the arc is a straight line (SVG 1.1 F.6.2)
            code = _LINE
        else:  # Line and any other linear segment
            row = (p0, p0, p3, p3)
            code = _LINE
        if row[0] == row[1] == row[2] == row[3]:
            continue
        if pending:
            closed.append(False)
            pending = False
            start = p0
        kinds.append(code)
        pts.append(row)
        subs.append(len(closed) - 1)
    return raw


_ARITY = {"M": 2, "L": 2, "H": 1, "V": 1, "C": 6, "S": 4, "Q": 4, "T": 2, "Z": 0}
_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_TOKEN = re.compile(rf"[MmZzLlHhVvCcSsQqTt]|{_NUM}")
_SEPARATORS = str.maketrans("", "", " \t\r\n\f,")


def raw_from_d(d: str) -> RawPath | None:
    """Parse path data without arcs quickly; return None if svgelements must do it.

    None is returned for data with arc commands and for malformed data (which
    svgelements renders up to the first error, as SVG asks).
    """
    if "a" in d or "A" in d:
        return None
    tokens = _TOKEN.findall(d)
    if _TOKEN.sub("", d).translate(_SEPARATORS):
        return None  # stray characters
    raw = RawPath([], [], [], [])
    kinds, pts, subs, closed = raw
    cur = start = 0j
    pending = True
    cmd = ""
    started = False
    rel = False
    need = 0
    args: list[float] = []
    prev_c2: complex | None = None  # last cubic control point (for S)
    prev_q: complex | None = None  # last quadratic control point (for T)
    for tok in tokens:
        if tok.isalpha():
            if args or (not started and tok not in "Mm"):
                return None  # incomplete arguments, or data not starting with M
            started = True
            up = tok.upper()
            rel = tok != up
            cmd, need = up, _ARITY[up]
            if cmd != "Z":
                continue
        else:
            if not cmd or cmd == "Z":
                return None  # a number without a command
            args.append(float(tok))
            if len(args) < need:
                continue
        # Execute one command with its arguments.
        base = cur if rel else 0j
        c2 = q = None
        if cmd == "Z":
            if not pending:
                _close(raw, cur, start)
            cur = start
            pending = True
            cmd = ""
            prev_c2 = prev_q = None
            continue
        if cmd == "M":
            cur = start = base + complex(args[0], args[1])
            pending = True
            cmd = "L"  # further pairs are implicit lines
            args = []
            prev_c2 = prev_q = None
            continue
        if cmd == "L":
            p3 = base + complex(args[0], args[1])
            row, code = (cur, cur, p3, p3), _LINE
        elif cmd == "H":
            p3 = complex(args[0] + (cur.real if rel else 0.0), cur.imag)
            row, code = (cur, cur, p3, p3), _LINE
        elif cmd == "V":
            p3 = complex(cur.real, args[0] + (cur.imag if rel else 0.0))
            row, code = (cur, cur, p3, p3), _LINE
        elif cmd == "C":
            c1 = base + complex(args[0], args[1])
            c2 = base + complex(args[2], args[3])
            p3 = base + complex(args[4], args[5])
            row, code = (cur, c1, c2, p3), _CUBIC
        elif cmd == "S":
            c1 = 2 * cur - prev_c2 if prev_c2 is not None else cur
            c2 = base + complex(args[0], args[1])
            p3 = base + complex(args[2], args[3])
            row, code = (cur, c1, c2, p3), _CUBIC
        elif cmd == "Q":
            q = base + complex(args[0], args[1])
            p3 = base + complex(args[2], args[3])
            row, code = (cur, q, q, p3), _QUAD
        else:  # T
            q = 2 * cur - prev_q if prev_q is not None else cur
            p3 = base + complex(args[0], args[1])
            row, code = (cur, q, q, p3), _QUAD
        args = []
        prev_c2, prev_q = c2, q
        if not (row[0] == row[1] == row[2] == row[3]):
            if pending:
                closed.append(False)
                pending = False
            kinds.append(code)
            pts.append(row)
            subs.append(len(closed) - 1)
        cur = p3
    if args:
        return None  # truncated arguments
    return raw


def assemble(raws: list[RawPath]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Convert collected paths to one cubic array.

    Returns
    -------
    cubics : ndarray of complex, shape (K, 4)
        The segments of all paths, one after another.
    subpaths : ndarray of int, shape (K,)
        Subpath of each segment within its own path.
    counts : ndarray of int, shape (len(raws),)
        Number of segments of each path.
    """
    counts = np.fromiter((len(r.pts) for r in raws), dtype=np.intp, count=len(raws))
    total = int(counts.sum())
    if total == 0:
        return np.zeros((0, 4), dtype=complex), np.zeros(0, dtype=np.intp), counts
    pts: list = []
    kinds: list = []
    subs: list = []
    for r in raws:
        pts += r.pts
        kinds += r.kinds
        subs += r.subs
    cubics = np.array(pts, dtype=complex).reshape(total, 4)
    _elevate(cubics, np.array(kinds, dtype=np.int8))
    return cubics, np.array(subs, dtype=np.intp), counts


def _to_arrays(raw: RawPath) -> tuple[np.ndarray, np.ndarray, tuple[bool, ...]]:
    if not raw.pts:
        return _empty()
    cubics, subpaths, _ = assemble([raw])
    return cubics, subpaths, tuple(raw.closed)


def cubics_from_path(path) -> tuple[np.ndarray, np.ndarray, tuple[bool, ...]]:
    """Convert an svgelements path (or any iterable of its segments) to cubic arrays.

    Parameters
    ----------
    path : svgelements.Path or iterable of svgelements segments
        The path, with its transform already applied to the points.

    Returns
    -------
    cubics : ndarray of complex, shape (k, 4)
        Control points of every drawn segment; zero-length segments are dropped.
    subpaths : ndarray of int, shape (k,)
        Subpath index of each segment (subpaths without segments are dropped).
    closed : tuple of bool
        Whether each subpath ends with ``Z``.  A closing segment back to the
        subpath's start is added to ``cubics`` when the subpath does not end there.
    """
    return _to_arrays(raw_from_segments(path))


def _elevate(cubics: np.ndarray, kinds: np.ndarray) -> None:
    """Turn line and quadratic rows (``p0 p0 p3 p3`` / ``p0 q q p3``) into exact cubics, in place."""
    with np.errstate(invalid="ignore", over="ignore"):
        _elevate_rows(cubics, kinds)


def _elevate_rows(cubics: np.ndarray, kinds: np.ndarray) -> None:
    line = kinds == _LINE
    if line.any():
        p0, p3 = cubics[line, 0], cubics[line, 3]
        d = p3 - p0
        cubics[line, 1] = p0 + d / 3.0
        cubics[line, 2] = p0 + 2.0 * d / 3.0
    quad = kinds == _QUAD
    if quad.any():
        p0, q, p3 = cubics[quad, 0], cubics[quad, 1], cubics[quad, 3]
        cubics[quad, 1] = p0 + 2.0 / 3.0 * (q - p0)
        cubics[quad, 2] = p3 + 2.0 / 3.0 * (q - p3)


def cubics_from_d(d: str) -> tuple[np.ndarray, np.ndarray, tuple[bool, ...]]:
    """Parse SVG path data into cubic arrays (see :func:`cubics_from_path`).

    Raises
    ------
    SvgError
        If the path data cannot be parsed.
    """
    raw = raw_from_d(d)
    if raw is not None:
        return _to_arrays(raw)
    from svgelements import Path

    snippet = d if len(d) <= 40 else d[:37] + "..."
    try:
        return cubics_from_path(Path(d))
    except SVGELEMENTS_ERRORS as exc:
        raise SvgError(f"invalid path data {snippet!r}") from exc


def _collinear_thirds(cubics: np.ndarray, tol: float) -> np.ndarray:
    """Return a mask of segments whose control points lie at 1/3 and 2/3 of the chord."""
    p0, c1, c2, p3 = cubics.T
    d = p3 - p0
    return (np.abs(c1 - (p0 + d / 3.0)) <= tol) & (np.abs(c2 - (p0 + 2.0 * d / 3.0)) <= tol)


def d_from_cubics(
    cubics: np.ndarray,
    subpaths: np.ndarray | None = None,
    closed: tuple[bool, ...] | list[bool] = (),
    precision: int = DEFAULT_PRECISION,
) -> str:
    """Write cubic arrays as compact absolute SVG path data.

    Segments whose control points sit at 1/3 and 2/3 of their chord are written as
    ``L``; a closed subpath's final straight segment back to its start is written
    as ``Z``.  Numbers have ``precision`` significant digits (relative error at most
    ``0.5 * 10**(1 - precision)``), and values below ``1e-12`` of the path's extent
    are written as ``0``.

    Parameters
    ----------
    cubics : ndarray of complex, shape (k, 4)
    subpaths : ndarray of int, shape (k,), optional
        Subpath of each segment (default: one subpath).
    closed : sequence of bool
        Whether each subpath is closed (missing entries: open).
    precision : int
        Significant digits of the numbers written.

    Returns
    -------
    str
        Path data such as ``"M0 0 L10 0 C12 1 12 4 10 5 Z"`` (empty for no segments).
    """
    cubics = np.asarray(cubics, dtype=complex).reshape(-1, 4)
    k = len(cubics)
    if k == 0:
        return ""
    subpaths = np.zeros(k, dtype=np.intp) if subpaths is None else np.asarray(subpaths).reshape(k)
    scale = float(np.max(np.abs(cubics))) or 1.0
    tol = 1e-9 * scale
    xy = np.stack([cubics.real, cubics.imag], axis=-1) + 0.0  # (k, 4, 2); + 0.0 turns -0.0 into 0.0
    xy[np.abs(xy) < 1e-12 * scale] = 0.0

    p_start = cubics[:, 0]
    first = np.ones(k, dtype=bool)
    first[1:] = (subpaths[1:] != subpaths[:-1]) | (np.abs(p_start[1:] - cubics[:-1, 3]) > tol)
    last = np.ones(k, dtype=bool)
    last[:-1] = subpaths[1:] != subpaths[:-1]
    is_line = _collinear_thirds(cubics, tol)
    sub_start = p_start[first][np.cumsum(first) - 1]  # start of the contour of each segment
    n_sub = int(subpaths.max()) + 1
    closed_arr = np.zeros(n_sub, dtype=bool)
    flags = np.asarray(tuple(closed)[:n_sub], dtype=bool)
    closed_arr[: flags.size] = flags
    seg_closed = closed_arr[subpaths] & last
    # The last straight segment of a closed subpath, back to its start, is implied by Z
    # (unless it is the contour's only segment).
    as_z = seg_closed & is_line & (np.abs(cubics[:, 3] - sub_start) <= tol) & ~first

    num = f"%.{int(precision)}g"
    pair = f"{num} {num}"
    pieces = np.where(is_line, f"L{pair} ", f"C{pair} {pair} {pair} ")
    pieces[as_z] = ""
    text = np.char.add(np.char.add(np.where(first, f"M{pair} ", ""), pieces), np.where(seg_closed, "Z ", ""))
    template = "".join(text.tolist())
    # Per segment, the numbers its commands write: start (M), controls (C), end (L, C).
    use_c = ~is_line & ~as_z
    mask = np.stack([first, use_c, use_c, ~as_z], axis=1)  # (k, 4) over p0, c1, c2, p3
    values = xy[mask]  # row-major: segment by segment, points in order
    return (template % tuple(values.ravel().tolist())).rstrip()
