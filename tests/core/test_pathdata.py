"""Tests of the vectorised path-data reader: numbers, commands, arcs, errors, memory."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lsys_core.errors import SvgError
from lsys_core.geometry.numbers import lex, numbers_from_text
from lsys_core.geometry.pathdata import parse_path
from lsys_core.geometry.paths import cubics_from_d, path_from_d


@pytest.mark.parametrize(
    ("text", "values", "error"),
    [
        ("1-2.5.5e3 1e-5,-.5", [1, -2.5, 500, 1e-5, -0.5], -1),
        ("1.5.5", [1.5, 0.5], -1),
        ("1e5.5", [1e5, 0.5], -1),
        ("5. -.5E+2", [5, -50], -1),
        ("1 x 2", [1], 2),
        ("3 -", [3], 2),
        ("1e", [], 0),
        ("1e5e5", [], 0),
        (".e5", [], 0),
        ("+-3", [], 0),
        ("12345678901234567 1e400", [12345678901234567, float("inf")], -1),
    ],
)
def test_number_lists(text, values, error):
    got, err = numbers_from_text(text)
    assert got.tolist() == pytest.approx(values)
    assert err == error


def test_lexing_in_chunks_gives_the_same_tokens():
    text = " ".join(f"L{i * 0.37:.3f}-{i}e-1,{i}.5.25" for i in range(3000))
    whole, chunked = lex(text), lex(text, chunk=97)
    assert np.array_equal(whole.values, chunked.values)
    assert np.array_equal(whole.starts, chunked.starts)
    assert np.array_equal(whole.letter_pos, chunked.letter_pos)
    assert whole.values.size == 12000  # "L0.370-1e-1,1.5.25": 0.37, -1e-1, 1.5, .25


def test_chunks_lexed_on_several_workers_give_the_same_tokens_and_limit():
    from lsys_core import parallel
    from lsys_core.errors import LimitError

    text = " ".join(f"L{i * 0.37:.3f}-{i}e-1,{i}.5.25 x" for i in range(3000))  # with errors
    try:
        parallel.set_jobs(1)
        one = lex(text, chunk=97)
        for jobs in (2, 3):
            parallel.set_jobs(jobs)
            got = lex(text, chunk=97)
            assert all(np.array_equal(x, y) for x, y in zip(got, one, strict=True))
            with pytest.raises(LimitError, match="more than 5,000 numbers"):
                lex(text, chunk=97, max_numbers=5000)
    finally:
        parallel.set_jobs(None)
    assert one.errors.size == 3000


def _reference(d: str) -> list[tuple[complex, complex, complex, complex, str]]:
    """A plain sequential reading of simple, well-formed data (no arcs) after the SVG spec."""
    toks = d.replace(",", " ").split()
    out, cur, start, prev_c, prev_q, i = [], 0j, 0j, None, None, 0
    cmd = ""
    while i < len(toks):
        if toks[i].isalpha():
            cmd = toks[i]
            i += 1
            if cmd in "Zz":
                if cur != start:
                    out.append((cur, cur, start, start, "L"))
                cur, prev_c, prev_q = start, None, None
                continue
        rel = cmd.islower()
        base = cur if rel else 0j
        up = cmd.upper()
        n = {"M": 2, "L": 2, "H": 1, "V": 1, "C": 6, "S": 4, "Q": 4, "T": 2}[up]
        a = [float(t) for t in toks[i : i + n]]
        i += n
        pc, pq = None, None
        if up == "M":
            cur = start = base + complex(a[0], a[1])
            cmd = "l" if rel else "L"
        elif up in "LHV":
            if up == "L":
                end = base + complex(a[0], a[1])
            elif up == "H":
                end = complex(a[0] + (cur.real if rel else 0), cur.imag)
            else:
                end = complex(cur.real, a[0] + (cur.imag if rel else 0))
            out.append((cur, cur, end, end, "L"))
            cur = end
        elif up in "CS":
            c1 = (
                base + complex(a[0], a[1]) if up == "C" else (2 * cur - prev_c if prev_c is not None else cur)
            )
            rest = a[2:] if up == "C" else a
            c2, end = base + complex(rest[0], rest[1]), base + complex(rest[2], rest[3])
            out.append((cur, c1, c2, end, "C"))
            cur, pc = end, c2
        else:
            q = base + complex(a[0], a[1]) if up == "Q" else (2 * cur - prev_q if prev_q is not None else cur)
            end = base + complex(a[-2], a[-1])
            out.append((cur, q, q, end, "Q"))
            cur, pq = end, q
        prev_c, prev_q = pc, pq
    return [row for row in out if not (row[0] == row[1] == row[2] == row[3])]  # zero length: dropped


_COMMAND = st.sampled_from("MmLlHhVvCcSsQqTtZz")
_ARGS = {"M": 2, "L": 2, "H": 1, "V": 1, "C": 6, "S": 4, "Q": 4, "T": 2, "Z": 0}


@st.composite
def _path_data(draw):
    parts = [f"M {draw(st.integers(-50, 50))} {draw(st.integers(-50, 50))}"]
    for _ in range(draw(st.integers(1, 12))):
        c = draw(_COMMAND)
        n = _ARGS[c.upper()]
        reps = draw(st.integers(1, 2)) if n else 1
        args = [str(draw(st.integers(-50, 50))) for _ in range(n * reps)]
        parts.append(" ".join([c, *args]))
    return " ".join(parts)


@settings(max_examples=300, deadline=None)
@given(_path_data())
def test_commands_resolve_like_a_sequential_reading(d):
    cubics, _, _ = cubics_from_d(d)
    ref = _reference(d)
    assert cubics.shape[0] == len(ref)
    for got, (p0, c1, c2, p3, kind) in zip(cubics, ref, strict=True):
        assert got[0] == pytest.approx(p0) and got[3] == pytest.approx(p3)
        if kind == "L":  # a line: control points at thirds
            assert got[1] == pytest.approx(p0 + (p3 - p0) / 3)
        elif kind == "Q":  # a quadratic, elevated
            assert got[1] == pytest.approx(p0 + 2 / 3 * (c1 - p0))
        else:
            assert got[1] == pytest.approx(c1) and got[2] == pytest.approx(c2)


def test_smooth_curves_reflect_only_their_own_kind():
    # S after T (and T after S) starts at the current point, as the spec says.
    cubics, _, _ = cubics_from_d("M0 0 T10 0 S20 10 30 0")
    assert cubics[1, 1] == pytest.approx(10)
    cubics, _, _ = cubics_from_d("M0 0 Q5 5 10 0 T20 0 T30 0")
    assert cubics[2, 1] == pytest.approx(20 + 2 / 3 * ((25 + 5j) - 20))


def test_relative_moves_after_close_start_from_the_subpath_start():
    cubics, subpaths, closed = cubics_from_d("M10 10 l5 0 l0 5 z m1 1 l2 0 z m1 1 l2 0")
    assert closed == (True, True, False)
    starts = [cubics[subpaths == k][0, 0] for k in range(3)]
    assert starts == [10 + 10j, 11 + 11j, 12 + 12j]


def _ellipse_distance(points, centre, rx, ry, phi):
    local = (points - centre) * np.exp(-1j * np.deg2rad(phi))
    return np.abs(np.hypot(local.real / rx, local.imag / ry) - 1)


@pytest.mark.parametrize(
    ("d", "centre", "rx", "ry", "phi"),
    [
        ("M0 0 A10 10 0 0 1 20 0", 10, 10, 10, 0),
        ("M0 0 A10 10 0 1 0 20 0", 10, 10, 10, 0),
        ("M0 0 a5 3 30 1 1 0.5 0.25", None, None, None, 30),
        ("M0 0 A1 1 0 0 1 20 0", 10, 10, 10, 0),  # radii grown to fit
    ],
)
def test_arcs_lie_on_their_ellipse(d, centre, rx, ry, phi):
    cubics, _, _ = cubics_from_d(d)
    t = np.linspace(0, 1, 50)[:, None]
    pts = (1 - t) ** 3 * cubics[:, 0] + 3 * (1 - t) ** 2 * t * cubics[:, 1]
    pts = (pts + 3 * (1 - t) * t**2 * cubics[:, 2] + t**3 * cubics[:, 3]).ravel()
    if centre is None:  # check against an independent evaluation of the arc
        from svgelements import Arc, Path

        arc = next(s for s in Path(d) if isinstance(s, Arc))
        centre, rx, ry = complex(arc.center.x, arc.center.y), arc.rx, arc.ry
    assert _ellipse_distance(pts, centre, rx, ry, phi).max() < 1e-5
    assert cubics[0, 0] == 0 and abs(cubics[-1, 3] - cubics_from_d(d)[0][-1, 3]) == 0


def test_arc_flags_without_separators_and_zero_radius():
    a, _, _ = cubics_from_d("M1 2a1 1 0 011 1")
    b, _, _ = cubics_from_d("M1 2a1 1 0 0 1 1 1")
    assert np.allclose(a, b)
    line, _, _ = cubics_from_d("M0 0 A0 5 0 0 1 10 0")
    assert line.shape == (1, 4) and line[0, 3] == 10


@pytest.mark.parametrize(
    ("d", "segments", "message"),
    [
        ("M10 10 L20 20 30", 1, "incomplete arguments"),
        ("M10 10 L20 20 L 30 x", 1, "unexpected character"),
        ("M10 10 L20 20 Z 5 5", 2, "numbers after Z"),
        ("L10 10", 0, "must begin with a move"),
        ("M1 2 a1 1 0 2 1 1 1", 0, "incomplete arguments"),
        ("M0 0 L10 0 1e", 1, "unexpected character"),
    ],
)
def test_errors_draw_up_to_the_last_complete_command(d, segments, message):
    path, error = path_from_d(d)
    assert path.cubics.shape[0] == segments
    assert message in error
    with pytest.raises(SvgError, match=message):
        cubics_from_d(d)  # the strict reader (rule files) refuses


def test_memory_is_proportional_to_the_commands():
    """10,000 and 100,000 line commands: peak traced memory per command stays under 400 bytes."""
    peaks = []
    for n in (10_000, 100_000):
        d = "M0 0 " + " ".join(f"L{i % 1000}.5 {i // 1000}" for i in range(n))
        tracemalloc.start()
        cubics, _, _ = cubics_from_d(d)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        assert cubics.shape == (n, 4)
        peaks.append(peak / n)
    assert max(peaks) < 400, peaks


def test_table_rows_are_absolute():
    table = parse_path("m1 1 h2 v2 z")
    assert table.error is None
    assert table.pts[:, 3].tolist() == [1 + 1j, 3 + 1j, 3 + 3j, 1 + 1j]


_TOKENS = st.sampled_from(
    ["1", "12", "-3", "+4", ".5", "1.", "1.5", "1e3", "1E-2", "2e+1", "e", ".", "-", "1.5.5", "x"]
)
_SEPS = st.sampled_from(["", " ", ",", " , ", "\t", "\n"])


@settings(max_examples=400, deadline=None)
@given(st.lists(st.tuples(st.one_of(_TOKENS, _COMMAND), _SEPS), max_size=20), st.booleans())
def test_the_short_path_lexes_like_the_vectorised_one(tokens, letters):
    import lsys_core.geometry.numbers as numbers

    text = "".join(t + s for t, s in tokens)
    quick = numbers._lex_short(text.encode(), letters)
    whole = numbers._lex_chunk(np.frombuffer(text.encode(), np.uint8), letters)
    if quick is None:  # not well-formed: the vectorised lexer reports an error
        assert whole[4].size > 0
        return
    for got, want in zip(quick, whole, strict=True):
        assert np.array_equal(got, want), text
