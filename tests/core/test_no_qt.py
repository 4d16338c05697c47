"""lsys_core never imports Qt (or the app), and the CLI path does not import skia."""

from __future__ import annotations

import subprocess
import sys

CODE = """
import sys, pkgutil, importlib, lsys_core
for m in pkgutil.walk_packages(lsys_core.__path__, 'lsys_core.'):
    importlib.import_module(m.name)
bad = [m for m in sys.modules if m.startswith(('PySide6', 'shiboken6', 'app'))]
print(','.join(bad))
"""


def test_core_imports_no_qt() -> None:
    out = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == ""


def test_infer_path_does_not_import_skia() -> None:
    code = (
        "import sys, lsys_core.cli, lsys_core.pipeline, lsys_core.svg.parse, lsys_core.derive.derivation; "
        "print('skia' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.stdout.strip() == "False"


def test_an_inference_to_rules_loads_no_renderer_and_no_image_filters(tmp_path) -> None:
    # Both are imported where they are used (a PNG to write; distance fields of near-identical
    # terminals): an inference of exact copies that writes only rules loads neither.
    svg = tmp_path / "a.svg"
    leaves = "".join(f'<path d="M{20 * i},0 q5,-8 14,-2 q-5,4 -14,2 z"/>' for i in range(6))
    svg.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 200 40">{leaves}</svg>')
    out = tmp_path / "a.lsys"
    code = (
        "import sys\nfrom lsys_core.cli import main\n"
        f"status = main(['-q', 'infer', {str(svg)!r}, '-o', {str(out)!r}])\n"
        "print(status, 'lsys_core.render.raster' in sys.modules, 'scipy.ndimage' in sys.modules)"
    )
    got = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert got.stdout.split() == ["0", "False", "False"], got.stderr
    assert "->" in out.read_text()
