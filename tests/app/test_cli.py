"""``lsys-editor FILE --screenshot OUT.png``: a PNG of the whole window once everything is computed."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _run(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    env = dict(os.environ, QT_QPA_PLATFORM="offscreen", PYTHONPATH=str(ROOT))
    env["XDG_CONFIG_HOME"] = env["XDG_DATA_HOME"] = str(Path(args[-1]).parent)  # keep settings out of ~
    return subprocess.run(
        [sys.executable, "-m", "app", *args],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def test_screenshot_of_helix(corpus, tmp_path):
    from PySide6.QtGui import QImage

    out = tmp_path / "shot.png"
    proc = _run(str(corpus("helix.svg")), "--screenshot", str(out), "--size", "1200x800")
    assert proc.returncode == 0, proc.stderr
    image = QImage(str(out))
    assert (image.width(), image.height()) == (1200, 800)
    # the canvas shows the helix: dark green strokes somewhere in the middle of the window
    green = sum(
        1
        for x in range(300, 900, 3)
        for y in range(100, 700, 3)
        if (c := image.pixelColor(x, y)).green() > c.red() + 30 and c.green() > c.blue() + 30
    )
    assert green > 20


def test_screenshot_of_missing_file_fails_with_message(tmp_path):
    proc = _run(str(tmp_path / "nope.svg"), "--screenshot", str(tmp_path / "x.png"))
    assert proc.returncode != 0
    assert "no such file" in proc.stderr
    assert not (tmp_path / "x.png").exists()


def test_screenshot_of_unreadable_svg_fails_with_message(tmp_path):
    bad = tmp_path / "bad.svg"
    bad.write_text("not an svg at all", encoding="utf-8")
    proc = _run(str(bad), "--screenshot", str(tmp_path / "x.png"))
    assert proc.returncode == 1
    assert "bad.svg" in proc.stderr


def test_screenshot_runs_steps_then_exits_without_asking_to_save(tmp_path):
    """Steps edit the rules (a handle drag); the run still ends by itself with a picture."""
    out = tmp_path / "drag.png"
    example = ROOT / "resources" / "examples" / "facade.svg"
    args = ("--size", "1000x700", "--show", "cards,structure", "--select", "3", "--drag", "40,0")
    proc = _run(str(example), "--screenshot", str(out), *args, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert out.stat().st_size > 0


def test_screenshot_step_arguments_are_checked(tmp_path):
    example = ROOT / "resources" / "examples" / "facade.svg"
    proc = _run(str(example), "--screenshot", str(tmp_path / "x.png"), "--show", "nope")
    assert proc.returncode != 0 and "--show takes" in proc.stderr
    assert not (tmp_path / "x.png").exists()


def test_editor_sets_numpy_variables_before_numpy_loads():
    """``lsys-editor`` sets numpy's sort and page variables (inherited by its inference process)
    before numpy loads: AVX2 sort on Zen 4, small pages in a virtual machine."""
    zen4_vm = "vendor_id\t: AuthenticAMD\ncpu family\t: 25\nflags\t\t: avx512f hypervisor\n"
    code = (
        "import os, sys, lsys_core.cpu as c\n"
        f"c._processor = lambda: {zen4_vm!r}\n"
        "c.numpy_version = lambda: (2, 4)\n"
        "from lsys_editor.__main__ import main\n"
        "assert 'numpy' not in sys.modules\n"
        "try:\n"
        "    main(['--version'])\n"
        "except SystemExit:\n"
        "    pass\n"
        "print(os.environ.get(c.VARIABLE), os.environ.get(c.HUGEPAGE))\n"
    )
    env = {
        k: v for k, v in os.environ.items() if k not in ("NPY_DISABLE_CPU_FEATURES", "NUMPY_MADVISE_HUGEPAGE")
    }
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.splitlines()[-1] == "X86_V4 AVX512_ICL AVX512_SPR 0"
