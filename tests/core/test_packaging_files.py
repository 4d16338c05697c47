"""Packaging metadata: desktop entry, AppStream metainfo, icons and the PyInstaller spec agree."""

from __future__ import annotations

import ast
import configparser
import shutil
import struct
import subprocess
import tomllib
import xml.etree.ElementTree as ET

import pytest

from lsys_core.derive.derivation import derive
from lsys_core.grammar import parse_grammar
from lsys_core.svg.parse import load_svg

from .shared import ROOT

APP_ID = "io.github.lsys_editor.LsysEditor"
RES = ROOT / "resources"
PACKAGING = ROOT / "packaging"
ICONS = RES / "icons" / "hicolor"
DESKTOP = RES / f"{APP_ID}.desktop"
METAINFO = RES / f"{APP_ID}.metainfo.xml"
SIZES = (16, 32, 48, 64, 128, 256)


def desktop_entry() -> configparser.SectionProxy:
    parser = configparser.ConfigParser(interpolation=None, strict=True)
    parser.optionxform = str  # keys are case-sensitive
    parser.read_string(DESKTOP.read_text(encoding="utf-8"))
    return parser["Desktop Entry"]


def scripts() -> dict[str, str]:
    with open(ROOT / "pyproject.toml", "rb") as fh:
        return tomllib.load(fh)["project"]["scripts"]


def png_size(data: bytes) -> tuple[int, int]:
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def test_desktop_entry_launches_the_editor_with_an_existing_icon() -> None:
    entry = desktop_entry()
    assert entry["Type"] == "Application"
    assert entry["Name"] and entry["Comment"]
    exe = entry["Exec"].split()[0]
    assert exe == "lsys-editor" and exe in scripts()
    assert entry["Icon"] == APP_ID
    assert "Graphics" in entry["Categories"].split(";")
    assert "image/svg+xml" in entry["MimeType"].split(";")
    assert (ICONS / "scalable" / "apps" / f"{entry['Icon']}.svg").is_file()
    for size in SIZES:
        png = ICONS / f"{size}x{size}" / "apps" / f"{entry['Icon']}.png"
        assert png_size(png.read_bytes()) == (size, size), png


def test_scalable_icon_is_the_derivation_of_its_lsystem() -> None:
    grammar = parse_grammar((RES / "icons" / "icon.lsys").read_text(encoding="utf-8"))
    icon = load_svg(ICONS / "scalable" / "apps" / f"{APP_ID}.svg")
    assert len(icon.elements) == len(derive(grammar)) > 10


def test_metainfo_names_the_app_its_launcher_and_both_binaries() -> None:
    root = ET.parse(METAINFO).getroot()
    assert root.tag == "component" and root.get("type") == "desktop-application"
    assert root.findtext("id") == APP_ID
    launchable = root.find("launchable")
    assert launchable.get("type") == "desktop-id"
    assert (RES / launchable.text).resolve() == DESKTOP.resolve()
    assert root.findtext("name") and root.findtext("summary")
    assert root.find("description/p") is not None
    assert sorted(b.text for b in root.findall("provides/binary")) == sorted(scripts())
    with open(ROOT / "pyproject.toml", "rb") as fh:
        project = tomllib.load(fh)["project"]
    assert root.findtext("project_license") == project["license"]
    assert root.find("releases/release").get("version") == project["version"]


def _entry_target(script: str) -> str:
    """Return ``module:function`` that a frozen entry script imports and calls."""
    tree = ast.parse((PACKAGING / script).read_text(encoding="utf-8"))
    imports = [n for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
    assert len(imports) == 1, script
    return f"{imports[0].module}:{imports[0].names[0].name}"


def test_spec_builds_both_entry_points_into_one_folder() -> None:
    spec = (PACKAGING / "lsys-editor.spec").read_text(encoding="utf-8")
    ast.parse(spec)
    assert "entry_editor.py" in spec and "entry_lsys.py" in spec
    assert 'name="lsys-editor"' in spec and 'name="lsys"' in spec
    assert spec.count("COLLECT(") == 1
    assert '"resources/examples"' in spec and '"resources/icons"' in spec
    assert _entry_target("entry_editor.py") == scripts()["lsys-editor"]
    assert _entry_target("entry_lsys.py") == scripts()["lsys"]


@pytest.mark.parametrize(
    "script", ["packaging/build.sh", "packaging/install.sh", "resources/examples/build.sh"]
)
def test_shell_scripts_parse(script: str) -> None:
    bash = shutil.which("bash")
    if bash is None:
        pytest.skip("bash not available")
    subprocess.run([bash, "-n", str(ROOT / script)], check=True, timeout=30)


def test_build_script_uses_its_own_venv_and_smoke_tests() -> None:
    text = (PACKAGING / "build.sh").read_text(encoding="utf-8")
    assert "build/package-venv" in text and ".venv/" not in text
    assert "--version" in text and "--screenshot" in text


@pytest.mark.parametrize(
    ("tool", "args", "path"),
    [
        ("desktop-file-validate", [], DESKTOP),
        ("appstreamcli", ["validate", "--no-net"], METAINFO),
    ],
)
def test_freedesktop_validators_accept_the_files(tool: str, args: list[str], path) -> None:
    exe = shutil.which(tool)
    if exe is None:
        pytest.skip(f"{tool} not installed (Debian: desktop-file-utils, appstream)")
    p = subprocess.run([exe, *args, str(path)], capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stdout + p.stderr
    assert "error" not in (p.stdout + p.stderr).lower()
