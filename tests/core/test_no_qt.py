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
