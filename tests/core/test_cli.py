"""The `lsys` command: contract of infer/derive/symmetrize/params and its error handling."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from .shared import CORPUS, ROOT, need

LSYS = [sys.executable, "-m", "lsys_core.cli"]


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([*LSYS, *args], capture_output=True, text=True, timeout=120, cwd=cwd or ROOT)


def test_version_and_help() -> None:
    assert run("--version").stdout.startswith("lsys ")
    assert "infer" in run("--help").stdout


def test_infer_writes_rules_svg_and_report(tmp_path) -> None:
    svg = need(CORPUS / "sequence5.svg")
    rules, out, rep = tmp_path / "r.lsys", tmp_path / "o.svg", tmp_path / "r.json"
    p = run("infer", str(svg), "-o", str(rules), "--svg", str(out), "--report", str(rep))
    assert p.returncode == 0, p.stderr
    report = json.loads(rep.read_text())
    assert report["elements"] == 5
    assert len(report["rules"]) == 2
    assert report["axiom"]
    for key in ("svg_import", "similarity", "transforms", "clustering", "rules", "derivation"):
        assert key in report["stages"]
    derived = tmp_path / "d.svg"
    assert run("derive", str(rules), "-o", str(derived)).returncode == 0
    assert derived.read_text().count("<use") == 5


@pytest.mark.parametrize(
    "doc",
    [
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 200 100" width="20" display="none">'
        '<rect width="9" height="9"/></svg>',
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 200 100" width="20"><title>t</title></svg>',
    ],
    ids=["display-none-root", "no-children"],
)
def test_a_document_that_draws_nothing_gives_empty_rules(tmp_path, doc) -> None:
    src, rules, out = tmp_path / "in.svg", tmp_path / "r.lsys", tmp_path / "o.svg"
    src.write_text(doc)
    p = run("infer", str(src), "-o", str(rules), "--svg", str(out), "--report", str(tmp_path / "r.json"))
    assert p.returncode == 0, p.stderr
    assert p.stderr.splitlines() == [f"lsys: warning: {src} draws nothing: it has no drawable elements"]
    assert "rect" not in out.read_text() and "<use" not in out.read_text()
    assert 'viewBox="0 0 200 100"' in out.read_text() and 'width="20"' in out.read_text()
    assert json.loads((tmp_path / "r.json").read_text())["elements"] == 0
    derived = tmp_path / "d.svg"
    p = run("derive", str(rules), "-o", str(derived))
    assert p.returncode == 0, p.stderr
    assert 'viewBox="0 0 200 100"' in derived.read_text() and "<path" not in derived.read_text()


def test_derive_set_and_randomize(tmp_path) -> None:
    rules = ROOT / "tests" / "data" / "helix_truth.lsys"
    out = tmp_path / "o.svg"
    p = run(
        "derive",
        str(rules),
        "-o",
        str(out),
        "--set",
        "axiom.0.3.m=9",
        "--randomize",
        "angle=3",
        "--seed",
        "4",
    )
    assert p.returncode == 0, p.stderr
    assert out.read_text().count("<use") == 10
    params = run("params", str(rules)).stdout
    assert "axiom.0.3.m" in params


@pytest.mark.parametrize(
    "args,needle",
    [
        (["derive", "missing.lsys", "-o", "X"], "cannot read"),
        (["derive", "BAD", "-o", "X"], "1:1"),
        (["derive", "HUGE", "-o", "X"], "element limit"),
        (["infer", "NOTSVG"], "error"),
        (["derive", "HUGE", "-o", "X", "--randomize", "angle=x"], "--randomize"),
    ],
)
def test_errors_are_one_line_and_keep_files(tmp_path, args, needle) -> None:
    (tmp_path / "BAD").write_text("this is not a grammar\n")
    (tmp_path / "HUGE").write_text(
        'lsys 1\nterminal A "M0 0 L1 0"\naxiom: P(1000000000)\nP(m): m > 0 -> A f(1) P(m-1)\nP(m): m == 0 -> A\n'
    )
    (tmp_path / "NOTSVG").write_bytes(b"\x00\x01binary junk")
    (tmp_path / "X").write_text("precious")
    p = run(*args, cwd=tmp_path)
    assert p.returncode == 1
    assert "Traceback" not in p.stderr
    assert p.stderr.startswith("lsys: error:")
    assert needle in p.stderr
    assert len(p.stderr.strip().splitlines()) == 1
    assert (tmp_path / "X").read_text() == "precious"


def test_usage_error_exits_2() -> None:
    p = run("derive")
    assert p.returncode == 2
    assert "Traceback" not in p.stderr


def test_main_in_process_leaves_the_garbage_collector_as_it_was(tmp_path) -> None:
    """``infer`` imports with the collector paused and freezes the modules; ``main`` undoes both
    (and gives back the interpreter's switch interval)."""
    import gc

    from lsys_core.cli import main

    src = tmp_path / "in.svg"
    src.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 20">'
        + "".join(f'<rect x="{10 * i}" y="5" width="5" height="5"/>' for i in range(6))
        + "</svg>"
    )
    assert gc.isenabled()
    interval = sys.getswitchinterval()
    assert main(["-q", "infer", str(src), "-o", str(tmp_path / "r.lsys")]) == 0
    assert gc.isenabled() and gc.get_freeze_count() == 0
    assert sys.getswitchinterval() == interval
    gc.disable()
    try:
        assert main(["-q", "infer", str(src), "-o", str(tmp_path / "r2.lsys")]) == 0
        assert not gc.isenabled()
    finally:
        gc.enable()
    assert (tmp_path / "r.lsys").read_bytes() == (tmp_path / "r2.lsys").read_bytes()
