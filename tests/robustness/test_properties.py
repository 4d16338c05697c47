"""Property-based tests: the SVG importer and the ``.lsys`` parser on generated junk.

Whatever the input, the only exceptions allowed are the project's own (:class:`LsysError`),
with one-line messages; results must satisfy their invariants (see ``oracles.py``).  numpy
warnings are errors here: they would be noise on the user's terminal.  The fixed examples
below are what ``make fuzz`` found, kept as regression tests.
"""

from __future__ import annotations

import gzip
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lsys_core.derive.derivation import derive
from lsys_core.errors import GrammarError, LimitError, LsysError, SvgError
from lsys_core.grammar import list_params, parse_grammar, set_param
from lsys_core.render import drawing_to_svg
from lsys_core.svg import parse_svg

from .generators import SHAPE, hostile_svgs, lsys_texts, svg, svg_bytes, svg_documents
from .oracles import check_lsys_text, check_scene, check_svg_import

pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")

# derandomized: the suite never flakes; `make fuzz` explores with fresh seeds
FAST = settings(
    max_examples=200, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow]
)


# ---------------------------------------------------------------------------
# Generated junk


@FAST
@given(svg_bytes())
def test_svg_importer_on_junk_bytes(data: bytes) -> None:
    check_svg_import(data)


@FAST
@given(svg_documents())
def test_svg_importer_on_random_documents(text: str) -> None:
    check_svg_import(text)


@FAST
@given(lsys_texts())
def test_lsys_parser_on_token_soup(text: str) -> None:
    check_lsys_text(text)


@FAST
@given(st.text(max_size=200))
def test_lsys_parser_on_any_text(text: str) -> None:
    check_lsys_text(text)


@FAST
@given(lsys_texts())
def test_parsed_junk_derives_and_exports_or_fails_cleanly(text: str) -> None:
    try:
        g = parse_grammar(text, check_paths=True)
    except GrammarError:
        return
    try:
        with np.errstate(all="ignore"):  # derive.py's own overflow warnings: see test_library_hostile
            drawing = derive(g, limit=20_000)
        out = drawing_to_svg(drawing)
    except LsysError as exc:
        assert "\n" not in str(exc)
        return
    assert out.startswith("<?xml") and "nan" not in out and "inf" not in out


_VALUES = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True), st.integers(-(2**40), 2**40), st.sampled_from(["x", None])
)


@FAST
@given(st.data())
def test_set_param_takes_any_value_or_refuses_it(data) -> None:
    g = parse_grammar(
        'lsys 1\nterminal A "M0 0 L1 0"\naxiom: f(2) P(4)\nP(m): m > 0 -> A *(0.9) +(m) f(1) P(m-1)\n'
    )
    keys = [p.key for p in list_params(g)] + ["m", "nope", "P.0.9.v", "axiom.0.0.dv", "P.x.1.v"]
    key = data.draw(st.sampled_from(keys))
    value = data.draw(_VALUES)
    try:
        changed = set_param(g, key, value)
    except GrammarError as exc:
        assert "\n" not in str(exc)
        return
    assert all(math.isfinite(p.value) for p in list_params(changed))


# ---------------------------------------------------------------------------
# Regression tests: inputs the fuzzer found, and what they must give now

FINDINGS = [
    # zero-size viewBox / viewport: svgelements divided by zero
    ("root viewBox 0 size", svg(SHAPE, 'width="0" viewBox="0 3,4 0"'), "ignored the viewBox"),
    ("root viewBox hex", svg(SHAPE, 'width="0" viewBox="0 0 0x10"'), "ignored the viewBox"),
    ("nested viewBox 0", svg(f'<svg viewBox="0 0 0 0">{SHAPE}</svg>{SHAPE}'), "ignored the viewBox"),
    ("root width 0", svg(SHAPE, 'width="0" height="0" viewBox="0 0 10 10"'), "ignored the width"),
    # font-relative root size: svgelements cannot resolve em without a font
    ("root height em", svg(SHAPE, 'width="177pt" height="100em" viewBox="0 0 10 10"'), "ignored the height"),
    # opacities: float overflow inside svgelements' colour code
    (
        "fill-opacity times opacity",
        svg('<g opacity="10"><path d="M0 0 L5 5" fill-opacity="1e308"/></g>'),
        None,
    ),
    ("stroke-opacity 1e999", svg('<path d="M0 0 L5 5" stroke="red" stroke-opacity="1e999"/>'), None),
    ("opacity in style sheet", svg('<style>path{fill-opacity:1e999}</style><path d="M0 0 L5 5"/>'), None),
    ("opacity in style", svg('<path d="M0 0 L5 5" style="stroke:red;stroke-opacity:-1e999"/>'), None),
    # malformed path data that crashed svgelements
    ("path words", svg(f'<path d="hello world"/>{SHAPE}'), "skipped 1 element: malformed path data"),
    ("path trailing junk", svg(f'<path d="M 1 1 hello"/>{SHAPE}'), "skipped 1 element: malformed path data"),
    ("path bad arc flag", svg(f'<path d="M0 0 A 5 5 0 2 3 10 10"/>{SHAPE}'), "malformed path data"),
    # an unreadable transform is ignored, as renderers do
    (
        "transform nan",
        svg(f'<g transform="matrix(nan 0 0 1 0 0)">{SHAPE}</g>'),
        "ignored the unreadable transform",
    ),
    # overflowing transforms: numpy warnings while composing matrices
    (
        "transform overflow",
        svg(f'<g transform="scale(1e300)"><g transform="scale(1e300)">{SHAPE}</g></g>{SHAPE}'),
        "non-finite or huge",
    ),
]


@pytest.mark.parametrize(("label", "data", "warning"), FINDINGS, ids=[f[0] for f in FINDINGS])
def test_fuzz_findings_import_cleanly(label: str, data: str, warning: str | None) -> None:
    scene = parse_svg(data)
    check_scene(scene)
    if warning is not None:
        assert any(warning in w for w in scene.warnings), scene.warnings
    for el in scene.elements:
        for part in el.style.split(";"):
            if "opacity" in part:
                assert 0.0 <= float(part.split(":")[1]) <= 1.0


FINDING_ERRORS = [
    (  # the path is not displayed, so nothing is
        "inherited em length",
        svg('<path r="9e39em" display="none"><circle transform="translate(1) )("/></path>'),
        SvgError,
        "no drawable elements",
    ),
    ("truncated gzip", gzip.compress(svg(SHAPE).encode())[:30], SvgError, "truncated gzip data"),
    ("fan-out", hostile_svgs()["use_fan_out"](), LimitError, "fan-out"),
]


@pytest.mark.parametrize(
    ("label", "data", "error", "message"), FINDING_ERRORS, ids=[f[0] for f in FINDING_ERRORS]
)
def test_fuzz_findings_fail_with_a_located_one_line_error(label, data, error, message) -> None:
    with pytest.raises(error) as info:
        parse_svg(data)
    assert message in str(info.value)
    assert "\n" not in str(info.value)
