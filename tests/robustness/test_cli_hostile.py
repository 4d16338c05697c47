"""The ``lsys`` command on hostile input: a clean result or one ``lsys: error:`` line, never lost work.

Every case runs ``lsys`` in a subprocess under a 2 GiB address-space limit and a hang guard,
with every output file already present: a failing run must exit 1 with exactly one
``lsys: error: …`` line on stderr (and no traceback, no numpy noise) and leave those files
byte for byte as they were, with no temporary files beside them; a succeeding run must
write all of them.  The cases run concurrently in a thread pool (each in its own folder), so
the slow ones overlap with the rest.
"""

from __future__ import annotations

import json
import os
import re
import resource
import subprocess
import sys
import time
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from lsys_core.grammar import parse_grammar
from lsys_core.svg import parse_svg

from .generators import ROOT, hostile_rules, hostile_svgs

MEMORY_LIMIT = 2 << 30
# A hang guard, not a speed check: far above the slowest case's time on a loaded 2-core machine
# (about 27 s for overlapping_3000 before MDL).  Speed is measured by ``make bench``.
TIMEOUT = 600.0
#: Cases that take about half a minute of CPU alone: marked ``slow`` (``make test`` still runs them;
#: ``-m "not slow"`` skips them for a quick check), with a pytest time-out above the hang guard.
SLOW_CASES = frozenset({"svg-overlapping_3000"})
PRECIOUS = b"precious work \x00\xff that must survive\n"
GOOD_RULES = (ROOT / "tests" / "data" / "helix_truth.lsys").read_text(encoding="utf-8")
SVG_OUTPUTS = ("r.lsys", "o.svg", "o.png", "rep.json")
INFER = ("infer", "in.svg", "-o", "r.lsys", "--svg", "o.svg", "--png", "o.png", "--report", "rep.json")
DERIVE = ("derive", "r.lsys", "-o", "o.svg", "--png", "o.png")


@dataclass(frozen=True)
class Case:
    """One run of ``lsys``: input files, arguments, pre-existing outputs and the expected outcome."""

    name: str
    argv: tuple[str, ...]
    inputs: dict[str, bytes | Callable[[], bytes]] = field(default_factory=dict)  # built when run
    outputs: tuple[str, ...] = ()
    error: str | None = None  # a regex the error line must match; None: the run must succeed
    warning: str | None = None  # a regex some warning line must match
    xfail: str | None = None

    def __str__(self) -> str:
        return self.name


@dataclass
class Result:
    """What a run did."""

    returncode: int | None
    stdout: str
    stderr: str
    seconds: float
    folder: Path


def _svg_case(name: str, data: Callable[[], bytes], error=None, warning=None, xfail=None) -> Case:
    return Case(f"svg-{name}", INFER, {"in.svg": data}, SVG_OUTPUTS, error, warning, xfail)


def _rules_case(name: str, text: str, error: str) -> Case:
    return Case(f"rules-{name}", DERIVE, {"r.lsys": text.encode("utf-8")}, ("o.svg", "o.png"), error)


def _cases() -> list[Case]:
    svgs = hostile_svgs()
    located = r"r\.lsys:\d+:\d+: .*"
    svg_errors = {
        "empty": "is empty",
        "whitespace": "is empty",
        "binary": "holds binary data",
        "png_magic": "holds binary data",
        "truncated": "not an SVG: .*not well-formed|no element found|unclosed token",
        "wrong_encoding": "not an SVG",
        "unknown_encoding": "not an SVG",
        "html": "root element is <html>",
        "corrupt_gzip": "corrupt gzip data",
        "gzip_bomb": "decompresses to more than 50,000,000 bytes",
        "billion_laughs": "entities are not allowed",
        "quadratic_blowup": "entity references expand to more than 10,000,000 bytes",
        "xxe": "entities are not allowed",
        "parameter_entity": "entities are not allowed|external references",
        "too_many_elements": "more than 200,000 elements",
        "too_large": "too large",
        "use_fan_out": r"fan-out",
        "deep_nesting": "nested more than 500 levels",
    }
    svg_ok = {
        "use_missing": None,
        # nothing drawable: empty rules and an empty drawing of the same canvas, as renderers show
        "use_cycle": "draws nothing",
        "only_text_images_defs": "draws nothing",
        "single_element": None,
        "two_elements": None,
        "non_finite": "skipped 2 elements: non-finite or huge coordinates",
        "huge_coordinates": None,
        "zero_length_paths": "skipped 4 elements: degenerate",
        "malformed_path_data": "skipped 3 elements: malformed path data",  # "nan" is no number in path data
        "use_self": "skipped a <use> that refers to itself",
        "invalid_transform": r"ignored the unreadable transform 'rotate\(foo\)' of <g>",
        "zero_viewbox": "ignored the viewBox '0 0 0 0'",
        "nested_zero_viewbox": "ignored the viewBox '0 0 0 0'",
        "degenerate_transforms": "skipped 2 elements: degenerate",
        "overflowing_opacity": None,
        "exact_duplicates": None,
        "overlapping_3000": None,
    }
    assert set(svg_errors) | set(svg_ok) == set(svgs), "every hostile SVG needs an expectation"
    cases = [_svg_case(n, svgs[n], error=e) for n, e in svg_errors.items()]
    cases += [_svg_case(n, svgs[n], warning=w) for n, w in svg_ok.items()]

    rules = hostile_rules()
    rule_errors = {
        "m_1e9": "element limit",
        "exponential_branching": "element limit",
        "overflowing_scale": "overflows in rule P",
        "overflowing_distance": "overflows in the axiom",
        "syntax_error": located + "expected '\\)'",
        "undefined_symbol": located + "undefined symbol 'Q'",
        "never_terminates": located + "rule P never terminates",
        "mutual_recursion": located + "never terminates",
        "m_too_big": located + "out of range",
        "scale_zero": located + "scale must be positive",
        "scale_negative": located + "scale must be positive",
        "nan": located + "non-finite number 'nan'",
        "overflowing_number": located + "number out of range '1e999'",
        "empty": located + "missing header",
        "binary": located + "unexpected character",
        "bad_terminal_path": located + "terminal A: invalid path data 'hello world'",
        "non_finite_terminal_path": located + "terminal A: path data has non-finite or huge coordinates",
    }
    assert set(rule_errors) == set(rules), "every hostile rule file needs an expectation"
    cases += [_rules_case(n, rules[n], e) for n, e in rule_errors.items()]
    cases.append(
        Case("params-bad-rules", ("params", "r.lsys"), {"r.lsys": b"lsys 1\naxiom: P(\n"}, (), located)
    )

    good = {"r.lsys": GOOD_RULES.encode("utf-8")}
    outs = ("o.svg", "o.png")

    def derive(name: str, extra: tuple[str, ...], error: str) -> Case:
        return Case(f"derive-{name}", (*DERIVE, *extra), good, outs, error)

    cases += [
        derive("set-m-1e9", ("--set", "m=1000000000"), "element limit"),
        derive("set-m-nan", ("--set", "m=nan"), "finite number"),
        derive("set-scale-0", ("--set", "P.0.2.v=0"), "scale must be positive"),
        derive("set-unknown", ("--set", "nope=1"), "unknown parameter 'nope'"),
        derive("set-junk", ("--set", "m=abc"), "must be a number"),
        derive("randomize-nan", ("--randomize", "angle=nan"), "--randomize"),
        derive("randomize-junk", ("--randomize", "wobble=3"), "--randomize"),
        derive("seed-negative", ("--randomize", "angle=3", "--seed", "-1"), "--seed"),
        derive("limit-0", ("--limit", "0"), "--limit"),
        derive("limit-absurd", ("--limit", str(10**15)), "--limit"),
        derive("limit-small", ("--limit", "5"), "element limit"),
    ]
    svg_in = {"in.svg": svgs["two_elements"]()}

    def infer(name: str, extra: tuple[str, ...], error: str) -> Case:
        return Case(f"infer-{name}", (*INFER, *extra), svg_in, SVG_OUTPUTS, error)

    cases += [
        infer("weight-nan", ("--wn", "nan"), "wn"),
        infer("weight-negative", ("--wh", "-1"), "wh"),
        infer("tolerance-0", ("--tolerance", "0"), "tolerance"),
        infer("similarity-huge", ("--similarity", "1e308"), "similarit"),
    ]
    sym = ("symmetrize", "in.svg", "-o", "o.svg", "--rules", "r.lsys")
    cases += [
        Case(
            "symmetrize-binary", sym, {"in.svg": svgs["binary"]()}, ("o.svg", "r.lsys"), "holds binary data"
        ),
        Case(
            "symmetrize-use-cycle",
            sym,
            {"in.svg": svgs["use_cycle"]()},
            ("o.svg", "r.lsys"),
            warning="draws nothing",
        ),
        Case("symmetrize-two-elements", sym, svg_in, ("o.svg", "r.lsys")),
        Case("infer-missing-input", ("infer", "nope.svg", "-o", "r.lsys"), {}, ("r.lsys",), "cannot read"),
        Case("infer-input-is-folder", ("infer", ".", "-o", "r.lsys"), {}, ("r.lsys",), "cannot read"),
        Case("derive-missing-rules", ("derive", "nope.lsys", "-o", "o.svg"), {}, ("o.svg",), "cannot read"),
        # never lose work: outputs that cannot be written are found before anything is written
        Case(
            "derive-output-folder-missing",
            ("derive", "r.lsys", "-o", "o.svg", "--png", "missing/o.png"),
            good,
            ("o.svg",),
            "cannot write missing/o.png: No such file or directory",
        ),
        Case(
            "infer-output-folder-missing",
            (*INFER[:-2], "--report", "missing/rep.json"),
            svg_in,
            SVG_OUTPUTS[:3],
            "cannot write missing/rep.json: No such file or directory",
        ),
        Case(
            "derive-output-is-a-folder",
            ("derive", "r.lsys", "-o", "o.svg", "--png", "sub"),
            good,
            ("o.svg", "sub/keep.txt"),
            "cannot write sub: Is a directory",
        ),
        Case(
            "derive-output-under-a-file",
            ("derive", "r.lsys", "-o", "o.svg", "--png", "o.svg/x.png"),
            good,
            ("o.svg",),
            "cannot write o.svg/x.png: Not a directory",
        ),
        Case(
            "infer-same-output-twice",
            ("infer", "in.svg", "-o", "r.lsys", "--svg", "./r.lsys"),
            svg_in,
            ("r.lsys",),
            "given twice",
        ),
    ]
    names = [c.name for c in cases]
    assert len(names) == len(set(names))
    return cases


CASES = _cases()


def _limit_memory() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))


def _limit_memory_low_priority() -> None:
    """Limit memory and yield the CPU to the other runs (for known-slow cases that time out anyway)."""
    _limit_memory()
    os.nice(10)


def _run(case: Case, folder: Path) -> Result:
    """Prepare the folder (inputs, precious outputs) and run ``lsys`` there."""
    folder.mkdir(parents=True)
    for name, data in case.inputs.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(data() if callable(data) else data)
    for name in case.outputs:
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_bytes(PRECIOUS)
    env = {k: v for k, v in os.environ.items() if k != "LSYS_DEBUG"}
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env["OPENBLAS_NUM_THREADS"] = env["OMP_NUM_THREADS"] = "1"  # the runs share the cores
    start = time.perf_counter()
    try:
        p = subprocess.run(
            [sys.executable, "-m", "lsys_core.cli", *case.argv],
            cwd=folder,
            capture_output=True,
            text=True,
            errors="replace",
            timeout=TIMEOUT,
            preexec_fn=_limit_memory_low_priority if case.xfail else _limit_memory,
            env=env,
        )
    except subprocess.TimeoutExpired as exc:
        err = exc.stderr.decode(errors="replace") if isinstance(exc.stderr, bytes) else exc.stderr or ""
        return Result(None, "", err, time.perf_counter() - start, folder)
    return Result(p.returncode, p.stdout, p.stderr, time.perf_counter() - start, folder)


@pytest.fixture(scope="module")
def runs(request, tmp_path_factory) -> dict[str, Future]:
    """Start the selected cases concurrently (slow ones first); map case name to its future."""
    module = sys.modules[__name__]
    selected = []
    for item in request.session.items:
        callspec = getattr(item, "callspec", None)
        if getattr(item, "module", None) is module and callspec is not None and "case" in callspec.params:
            selected.append(callspec.params["case"])
    selected.sort(key=lambda c: c.xfail is None)
    base = tmp_path_factory.mktemp("cli")
    pool = ThreadPoolExecutor(max_workers=(os.cpu_count() or 2) + 2)
    futures = {c.name: pool.submit(_run, c, base / c.name) for c in selected}
    yield futures
    pool.shutdown(wait=True, cancel_futures=True)


def _leftovers(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*.tmp"))


def _check_outputs_kept(case: Case, res: Result) -> None:
    for name in case.outputs:
        assert (res.folder / name).read_bytes() == PRECIOUS, f"{name} was changed by a failed run"
    assert _leftovers(res.folder) == []


def _check_outputs_written(case: Case, res: Result) -> None:
    f = res.folder
    assert _leftovers(f) == []
    for name in case.outputs:
        assert (f / name).read_bytes() != PRECIOUS, f"{name} was not written"
    if "r.lsys" in case.outputs:
        parse_grammar((f / "r.lsys").read_text(encoding="utf-8"), check_paths=True)
    empty = case.warning == "draws nothing"  # empty rules and an empty drawing, written all the same
    if "o.svg" in case.outputs:
        drawn = parse_svg((f / "o.svg").read_bytes(), allow_empty=True).elements
        assert len(drawn) == 0 if empty else len(drawn) >= 1
    if "o.png" in case.outputs:
        assert (f / "o.png").read_bytes().startswith(b"\x89PNG\r\n\x1a\n")
    if "rep.json" in case.outputs:
        elements = json.loads((f / "rep.json").read_text(encoding="utf-8"))["elements"]
        assert elements == 0 if empty else elements >= 1


def _params():
    for c in CASES:
        marks = [pytest.mark.xfail(strict=False, reason=c.xfail)] if c.xfail else []
        if c.name in SLOW_CASES:
            marks += [pytest.mark.slow, pytest.mark.timeout(TIMEOUT + 300)]
        yield pytest.param(c, id=c.name, marks=marks)


@pytest.mark.parametrize("case", list(_params()))
def test_hostile_cli_run(case: Case, runs) -> None:
    res = runs[case.name].result()
    assert res.returncode is not None, f"lsys did not finish within {TIMEOUT:g} s (hang guard)"
    lines = res.stderr.splitlines()
    assert "Traceback" not in res.stderr
    assert "internal error" not in res.stderr
    noise = [line for line in lines if not line.startswith("lsys: ")]
    assert noise == [], f"stray output on stderr: {noise[:3]}"
    errors = [line for line in lines if line.startswith("lsys: error: ")]
    warnings = [line for line in lines if line.startswith("lsys: warning: ")]
    summaries = [line for line in lines if line.startswith("lsys: inferred ")]
    assert len(errors) + len(warnings) + len(summaries) == len(lines)
    if case.error is not None:
        assert res.returncode == 1, res.stderr
        assert len(errors) == 1 and lines[-1] == errors[0], res.stderr
        assert re.search(case.error, errors[0]), f"{errors[0]!r} does not match {case.error!r}"
        _check_outputs_kept(case, res)
    else:
        assert res.returncode == 0, res.stderr
        assert errors == []
        if case.warning is not None:
            assert any(re.search(case.warning, w) for w in warnings), warnings
        _check_outputs_written(case, res)
