"""What ``pip install .`` installs: the packages, their data, the entry points and the dependencies."""

from __future__ import annotations

import ast
import importlib
import re
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest

from .shared import ROOT

with open(ROOT / "pyproject.toml", "rb") as _fh:
    PYPROJECT = tomllib.load(_fh)
SETUPTOOLS = PYPROJECT["tool"]["setuptools"]
#: Import name of every runtime dependency (distribution names differ for some).
IMPORT_NAMES = {"PySide6-Essentials": "PySide6", "skia-python": "skia"}


def source_folder(package: str) -> Path:
    """Folder of an installed package name in the checkout, through ``package-dir``."""
    mapping = SETUPTOOLS.get("package-dir", {})
    parts = package.split(".")
    for i in range(len(parts), 0, -1):
        head = ".".join(parts[:i])
        if head in mapping:
            return ROOT / mapping[head] / Path(*parts[i:])
    return ROOT / Path(*parts)


def test_the_editor_installs_under_a_project_name() -> None:
    assert SETUPTOOLS["package-dir"]["lsys_editor"] == "app"
    assert not any(p == "app" or p.startswith("app.") for p in SETUPTOOLS["packages"])
    scripts = PYPROJECT["project"]["scripts"]
    assert scripts["lsys-editor"] == "lsys_editor.__main__:main"


def test_packages_list_names_every_package_of_the_tree() -> None:
    found = {"lsys_editor", "lsys_editor.resources"}
    for top, name in ((ROOT / "lsys_core", "lsys_core"), (ROOT / "app", "lsys_editor")):
        for init in top.rglob("__init__.py"):
            rel = init.parent.relative_to(top)
            found.add(".".join([name, *rel.parts]))
    assert set(SETUPTOOLS["packages"]) == found


def test_package_data_is_there() -> None:
    for package, patterns in PYPROJECT["tool"]["setuptools"]["package-data"].items():
        folder = source_folder(package)
        for pattern in patterns:
            if pattern != "*.qss":  # the editor has no style sheet at the moment
                assert list(folder.glob(pattern)), f"{package}: nothing matches {pattern}"
    res = source_folder("lsys_editor.resources")
    assert (res / "examples" / "helix.svg").is_file()
    assert (
        res / "icons" / "hicolor" / "scalable" / "apps" / "io.github.lsys_editor.LsysEditor.svg"
    ).is_file()
    assert (ROOT / "lsys_core" / "py.typed").is_file()
    assert PYPROJECT["project"]["license"] == "MIT"
    assert (ROOT / "LICENSE").read_text(encoding="utf-8").startswith("MIT License")


def test_entry_points_resolve() -> None:
    for target in PYPROJECT["project"]["scripts"].values():
        module, func = target.split(":")
        module = re.sub(r"^lsys_editor\b", "app", module)  # the checkout's folder name
        assert callable(getattr(importlib.import_module(module), func))


def _imported_modules() -> set[str]:
    names = set()
    for path in [*(ROOT / "lsys_core").rglob("*.py"), *(ROOT / "app").rglob("*.py")]:
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names.update(a.name.split(".")[0] for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                names.add(node.module.split(".")[0])
    return names


def test_runtime_dependencies_are_the_imported_ones() -> None:
    deps = [re.split(r"[<>=!~ ;\[]", d, maxsplit=1)[0] for d in PYPROJECT["project"]["dependencies"]]
    imported = _imported_modules()
    for dist in deps:
        assert IMPORT_NAMES.get(dist, dist) in imported, f"{dist} is a dependency nothing imports"
    test_extra = " ".join(PYPROJECT["project"]["optional-dependencies"]["test"])
    for dist, name in (("scikit-learn", "sklearn"), ("shapely", "shapely")):
        assert name not in imported and dist not in deps and dist in test_extra


@pytest.mark.slow
def test_wheel_contents(tmp_path) -> None:
    p = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(tmp_path), str(ROOT)],
        capture_output=True,
        text=True,
        timeout=900,
    )
    if p.returncode != 0 and re.search(r"connection|No matching distribution|resolve", p.stderr, re.I):
        pytest.skip("the build backend cannot be fetched (offline)")
    assert p.returncode == 0, p.stderr
    (wheel,) = tmp_path.glob("*.whl")
    with zipfile.ZipFile(wheel) as zf:
        names = set(zf.namelist())
        entry_points = zf.read(next(n for n in names if n.endswith("entry_points.txt"))).decode()
    assert not any(n.startswith("app/") for n in names)
    for needed in (
        "lsys_editor/__main__.py",
        "lsys_editor/resources/examples/helix.svg",
        "lsys_editor/resources/examples/helix.lsys",
        "lsys_editor/resources/icons/hicolor/scalable/apps/io.github.lsys_editor.LsysEditor.svg",
        "lsys_editor/resources/icons/hicolor/48x48/apps/io.github.lsys_editor.LsysEditor.png",
        "lsys_core/py.typed",
        "lsys_core/cli/__main__.py",
    ):
        assert needed in names, needed
    assert any(n.endswith("licenses/LICENSE") for n in names)
    assert "lsys-editor = lsys_editor.__main__:main" in entry_points
