"""The ``lsys`` command behaves like a Unix tool: stdin/stdout, options anywhere, pipes, devices, links, limits."""

from __future__ import annotations

import os
import stat
import struct
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from .shared import ROOT

LSYS = [sys.executable, "-m", "lsys_core.cli"]
RULES = ROOT / "tests" / "data" / "helix_truth.lsys"
ROW = (
    '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 120 20" width="{w}" height="{h}">'
    + "".join(f'<rect x="{10 * i + 2}" y="5" width="6" height="10" fill="#36c"/>' for i in range(6))
    + "</svg>"
)
SVG = ROW.format(w="120", h="20").encode()


def run(*args, stdin: bytes = b"", cwd: Path | None = None, env: dict | None = None, **kw):
    return subprocess.run(
        [*LSYS, *map(str, args)],
        input=stdin,
        capture_output=True,
        timeout=300,  # a hang guard far above the ~2 s a run takes
        cwd=cwd or ROOT,
        env=env,
        **kw,
    )


def one_error(p: subprocess.CompletedProcess, needle: str) -> str:
    """Check ``p`` failed with exactly one clean ``lsys: error:`` line holding ``needle``; return it."""
    err = p.stderr.decode("utf-8", "replace")
    assert p.returncode == 1, err
    assert err.count("\n") == 1 and err.startswith("lsys: error: "), err
    assert "Traceback" not in err and "internal error" not in err and "Warning" not in err
    assert needle in err, err
    return err


# ---------------------------------------------------------------------------
# '-' is standard input and standard output


def test_infer_reads_stdin_and_writes_rules_to_stdout() -> None:
    p = run("infer", "-", "-o", "-", stdin=SVG)
    assert p.returncode == 0, p.stderr
    assert p.stdout.startswith(b"lsys 2\n") and b"->" in p.stdout


def test_infer_svg_to_stdout_prints_only_the_svg(tmp_path) -> None:
    p = run("infer", "-", "--svg", "-", stdin=SVG)
    assert p.returncode == 0, p.stderr
    assert p.stdout.startswith(b"<?xml") and p.stdout.rstrip().endswith(b"</svg>")
    assert b"lsys " not in p.stdout
    # and the SVG is a valid input again: a pipeline of two commands
    again = run("infer", "-", "-o", "-", stdin=p.stdout)
    assert again.returncode == 0 and again.stdout.startswith(b"lsys 2"), again.stderr


def test_derive_and_params_read_rules_from_stdin() -> None:
    rules = RULES.read_bytes()
    p = run("derive", "-", "-o", "-", stdin=rules)
    assert p.returncode == 0, p.stderr
    assert p.stdout.count(b"<use") == 120
    assert b"axiom.0.3.m" in run("params", "-", stdin=rules).stdout


def test_two_outputs_on_stdout_are_refused() -> None:
    one_error(run("infer", "-", "-o", "-", "--svg", "-", stdin=SVG), "standard output")


# ---------------------------------------------------------------------------
# Options anywhere


@pytest.mark.parametrize("order", ["after", "before"])
def test_verbose_before_or_after_the_subcommand(tmp_path, order) -> None:
    (tmp_path / "a.svg").write_bytes(SVG)
    args = ["infer", "a.svg", "-o", "r.lsys"]
    p = run(*(["-v", *args] if order == "before" else [*args, "-v"]), cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    lines = p.stderr.decode().splitlines()
    timings = [line for line in lines if line.endswith(" ms")]
    assert {line.split()[1] for line in timings} >= {"similarity", "clustering", "svg_import", "derivation"}
    # '-v' labels: durations in ms, the reproduction error as what it is (a fraction, not a duration)
    assert not any("reproduction" in line for line in timings)
    assert any(line.startswith("lsys: reproduction error") and "diagonal" in line for line in lines)


def test_quiet_after_the_subcommand_silences_warnings(tmp_path) -> None:
    svg = SVG.replace(b"</svg>", b'<path d="M0 0"/></svg>')  # a degenerate path: a warning
    (tmp_path / "a.svg").write_bytes(svg)
    assert b"warning" in run("infer", "a.svg", "-o", "r.lsys", cwd=tmp_path).stderr
    assert run("infer", "a.svg", "-o", "r.lsys", "-q", cwd=tmp_path).stderr == b""


# ---------------------------------------------------------------------------
# Pipes and devices


def test_closed_pipe_ends_quietly_with_the_sigpipe_status() -> None:
    r, w = os.pipe()
    os.close(r)  # the reader is gone before anything is written (`| head -1` after its line)
    try:
        p = subprocess.run([*LSYS, "params", str(RULES)], stdout=w, stderr=subprocess.PIPE, timeout=300)
    finally:
        os.close(w)
    assert p.stderr == b""
    assert p.returncode == 141  # 128 + SIGPIPE, what a shell shows for `cat` in the same place


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_full_device_is_one_line_error(tmp_path) -> None:
    one_error(run("derive", RULES, "-o", "/dev/full"), "cannot write /dev/full: No space left on device")
    with open("/dev/full", "wb") as full:
        p = subprocess.run([*LSYS, "params", str(RULES)], stdout=full, stderr=subprocess.PIPE, timeout=300)
    one_error(p, "cannot write standard output: No space left on device")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_output_writes_through_a_fifo(tmp_path) -> None:
    fifo = tmp_path / "out.svg"
    os.mkfifo(fifo)
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()), daemon=True)
    reader.start()
    p = run("derive", RULES, "-o", fifo)
    reader.join(300)
    assert p.returncode == 0, p.stderr
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode), "the FIFO was replaced by a regular file"
    assert got and got[0].count(b"<use") == 120


def test_devices_are_written_through_not_replaced() -> None:
    from lsys_core.io.write import _classify

    out = _classify(os.devnull, b"x")
    assert out.device == os.devnull and out.final is None  # opened and written, never renamed over


def test_output_symlink_writes_through_to_its_target(tmp_path) -> None:
    target = tmp_path / "real" / "drawing.svg"
    target.parent.mkdir()
    target.write_text("old")
    link = tmp_path / "link.svg"
    link.symlink_to(target)
    dangling = tmp_path / "dangling.svg"
    dangling.symlink_to(tmp_path / "real" / "new.svg")
    assert run("derive", RULES, "-o", link).returncode == 0
    assert run("derive", RULES, "-o", dangling).returncode == 0
    assert link.is_symlink() and dangling.is_symlink()
    assert target.read_text().count("<use") == 120
    assert (tmp_path / "real" / "new.svg").read_text().count("<use") == 120
    assert [p.name for p in tmp_path.rglob("*.tmp")] == []


# ---------------------------------------------------------------------------
# The user's own files


@pytest.mark.parametrize("how", ["same", "hardlink", "symlink", "dotted"])
def test_an_output_that_is_the_input_is_refused(tmp_path, how) -> None:
    src = tmp_path / "in.svg"
    src.write_bytes(SVG)
    out = {"same": src, "dotted": tmp_path / "." / "in.svg"}.get(how, tmp_path / "other.svg")
    if how == "hardlink":
        os.link(src, out)
    elif how == "symlink":
        out.symlink_to(src)
    for args in (["infer", src, "-o", out], ["infer", src, "--svg", out], ["symmetrize", src, "-o", out]):
        one_error(run(*args), "it is the input file")
    rules = tmp_path / "r.lsys"
    rules.write_bytes(RULES.read_bytes())
    one_error(run("derive", rules, "-o", rules), "it is the input file")
    assert src.read_bytes() == SVG and rules.read_bytes() == RULES.read_bytes()


def test_a_250_byte_output_name_works(tmp_path) -> None:
    name = "x" * 246 + ".svg"
    p = run("derive", RULES, "-o", name, cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / name).read_text().count("<use") == 120


# ---------------------------------------------------------------------------
# Bounded reading


@pytest.mark.parametrize(
    "args,needle",
    [
        (["derive", "/dev/zero", "-o", "o.svg"], "/dev/zero:1:1: unexpected character NUL"),
        (["params", "/dev/urandom"], "/dev/urandom:"),
        (["infer", "/dev/zero", "-o", "r.lsys"], "too large"),
    ],
)
def test_endless_devices_fail_fast(tmp_path, args, needle) -> None:
    if not os.path.exists(args[1]):
        pytest.skip(f"needs {args[1]}")
    one_error(run(*args, cwd=tmp_path), needle)
    assert not (tmp_path / "o.svg").exists() and not (tmp_path / "r.lsys").exists()


def test_sparse_huge_rules_file_is_refused_before_reading(tmp_path) -> None:
    big = tmp_path / "big.lsys"
    with open(big, "wb") as fh:
        fh.truncate(2 << 30)  # sparse: 2 GiB that take no disk space
    # the size in the message comes from the file's metadata, checked before any byte is read
    one_error(run("params", big), "big.lsys is too large (2,147,483,648 bytes; the limit is 20,000,000)")


def test_reading_stops_at_the_limit() -> None:
    from lsys_core.errors import LimitError
    from lsys_core.io import CHUNK, read_bytes

    class Endless:
        read_total = 0

        def read(self, n: int) -> bytes:
            Endless.read_total += n
            return b"<" * n

    with pytest.raises(LimitError, match="more than 3,000,000 bytes"):
        read_bytes(Endless(), limit=3_000_000)  # type: ignore[arg-type]
    assert Endless.read_total <= 3_000_000 + CHUNK


# ---------------------------------------------------------------------------
# Messages


def test_tolerance_out_of_range_is_a_clean_error(tmp_path) -> None:
    (tmp_path / "a.svg").write_bytes(SVG)
    one_error(run("infer", "a.svg", "--tolerance", "1e-300", cwd=tmp_path), "tolerance must be in")


@pytest.mark.parametrize("name", ["we\nird.svg", "\x1b[31mred.svg", "tab\there\u2028.svg"])
def test_file_names_are_escaped_in_messages(tmp_path, name) -> None:
    err = one_error(run("infer", name, cwd=tmp_path), "cannot read")
    assert "\x1b" not in err and "\t" not in err and "\u2028" not in err
    assert "$'" in err  # quoted the way `ls` quotes it


def test_quote_name_reads_back_in_a_shell() -> None:
    from lsys_core.quoting import quote_name

    assert quote_name("plain-name_1.svg") == "plain-name_1.svg"
    for name in ["a b.svg", "it's", "a\nb", "\x1b[0m", "x\\y", ""]:
        quoted = quote_name(name)
        assert quoted.isprintable()
        back = subprocess.run(["bash", "-c", f"printf %s {quoted}"], capture_output=True, text=True)
        assert back.stdout == name


# ---------------------------------------------------------------------------
# PNG output


def png_size(data: bytes) -> tuple[int, int]:
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


@pytest.mark.parametrize(
    "w,h,extra,size",
    [
        ("2in", "1in", [], (192, 96)),
        ("2in", "1in", ["--dpi", "300"], (600, 300)),
        ("50.8mm", "25.4mm", [], (192, 96)),
        ("144pt", "", [], (192, 96)),  # height from the aspect ratio
        ("100%", "100%", [], (120, 60)),  # relative: the viewBox size
        ("2in", "1in", ["--width", "50"], (50, 25)),
        ("2in", "1in", ["--height", "10"], (20, 10)),
    ],
)
def test_png_size_follows_document_units(tmp_path, w, h, extra, size) -> None:
    svg = ROW.format(w=w, h=h).replace('viewBox="0 0 120 20"', 'viewBox="0 0 120 60"')
    (tmp_path / "a.svg").write_text(svg.replace(' height=""', ""))
    p = run("infer", "a.svg", "-o", "r.lsys", "--png", "-", *extra, cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert png_size(p.stdout) == size


def test_png_background(tmp_path) -> None:
    import skia

    (tmp_path / "a.svg").write_bytes(SVG)
    for colour, corner in (("none", 0), ("white", 255), ("#ff000080", 128)):
        p = run("infer", "a.svg", "-o", "r.lsys", "--png", "o.png", "--background", colour, cwd=tmp_path)
        assert p.returncode == 0, p.stderr
        image = skia.Image.MakeFromEncoded(skia.Data.MakeWithCopy((tmp_path / "o.png").read_bytes()))
        assert image.toarray()[0, 0, 3] == corner
    one_error(
        run("infer", "a.svg", "--png", "o.png", "--background", "blurple", cwd=tmp_path), "--background"
    )
    one_error(run("infer", "a.svg", "--png", "o.png", "--dpi", "0", cwd=tmp_path), "--dpi")


def test_without_skia_png_names_the_missing_library_and_the_rest_works(tmp_path) -> None:
    fake = tmp_path / "fake" / "skia"
    fake.mkdir(parents=True)
    (fake / "__init__.py").write_text(
        'raise ImportError("libEGL.so.1: cannot open shared object file: No such file or directory")\n'
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(fake.parent), str(ROOT)])}
    (tmp_path / "a.svg").write_bytes(SVG)
    err = one_error(
        run("infer", "a.svg", "-o", "r.lsys", "--png", "o.png", cwd=tmp_path, env=env), "libEGL.so.1"
    )
    assert "libegl1" in err and not (tmp_path / "r.lsys").exists()
    p = run("infer", "a.svg", "-o", "r.lsys", "--svg", "o.svg", cwd=tmp_path, env=env)
    assert p.returncode == 0, p.stderr
    derived = run("derive", "r.lsys", "-o", "-", cwd=tmp_path, env=env)
    assert derived.returncode == 0 and derived.stdout.startswith(b"<?xml"), derived.stderr


# ---------------------------------------------------------------------------
# The editor's command line


@pytest.mark.parametrize("flag,needle", [("--version", "lsys-editor 0.1"), ("--help", "usage: lsys-editor")])
def test_editor_version_and_help_before_qt(tmp_path, flag, needle) -> None:
    fake = tmp_path / "PySide6"
    fake.mkdir()
    (fake / "__init__.py").write_text('raise ImportError("no Qt here")\n')
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT)])}
    p = subprocess.run(
        [sys.executable, "-m", "app", flag], capture_output=True, text=True, env=env, cwd=ROOT, timeout=300
    )
    assert p.returncode == 0, p.stderr
    assert needle in p.stdout
