"""Start-up check of the system libraries Qt's platform plugin needs (one apt-get line)."""

from __future__ import annotations

import pytest

from app import syscheck


@pytest.mark.parametrize(
    ("soname", "package"),
    [
        ("libxcb-cursor.so.0", "libxcb-cursor0"),
        ("libxcb-icccm.so.4", "libxcb-icccm4"),
        ("libxcb-keysyms.so.1", "libxcb-keysyms1"),
        ("libxcb-render-util.so.0", "libxcb-render-util0"),
        ("libxkbcommon-x11.so.0", "libxkbcommon-x11-0"),
        ("libX11-xcb.so.1", "libx11-xcb1"),
        ("libEGL.so.1", "libegl1"),
        ("libdbus-1.so.3", "libdbus-1-3"),
        ("libwayland-cursor.so.0", "libwayland-cursor0"),
        ("libglib-2.0.so.0", "libglib2.0-0"),
    ],
)
def test_sonames_map_to_debian_packages(soname, package):
    assert syscheck.debian_package(soname) == package


def test_the_plugins_qt_will_try():
    assert syscheck.platform_plugins({"QT_QPA_PLATFORM": "offscreen", "DISPLAY": ":0"}) == []
    assert syscheck.platform_plugins({"DISPLAY": ":0"}) == ["xcb"]
    assert syscheck.platform_plugins({"WAYLAND_DISPLAY": "wayland-0", "DISPLAY": ":0"}) == ["wayland", "xcb"]
    assert syscheck.platform_plugins({"QT_QPA_PLATFORM": "wayland;xcb"}) == ["wayland", "xcb"]
    assert syscheck.platform_plugins({}) == []


def test_ldd_output_is_read_for_missing_libraries(monkeypatch, tmp_path):
    (tmp_path / "libqxcb.so").write_bytes(b"")
    out = (
        "\tlibxcb-cursor.so.0 => /lib/libxcb-cursor.so.0 (0x1)\n"
        "\tlibxcb-icccm.so.4 => not found\n\tlibxcb-keysyms.so.1 => not found\n"
        "\tlibxcb-icccm.so.4 => not found\n"
    )

    class Done:
        stdout = out

    monkeypatch.setattr(syscheck.subprocess, "run", lambda *a, **k: Done())
    monkeypatch.setattr(syscheck.sys, "platform", "linux")
    assert syscheck.missing_libraries("xcb", tmp_path) == ["libxcb-icccm.so.4", "libxcb-keysyms.so.1"]
    assert syscheck.missing_libraries("wayland", tmp_path) is None  # no such plugin: cannot tell


def test_one_apt_get_line_names_every_missing_package(monkeypatch):
    libs = {
        "xcb": ["libxcb-cursor.so.0", "libxcb-icccm.so.4", "libxcb-keysyms.so.1"],
        "wayland": ["libwayland-cursor.so.0"],
    }
    monkeypatch.setattr(syscheck, "missing_libraries", lambda plugin: libs[plugin])
    message = syscheck.problem({"WAYLAND_DISPLAY": "w", "DISPLAY": ":0"})
    lines = [line for line in message.splitlines() if "apt-get" in line]
    assert lines == ["    sudo apt-get install libxcb-cursor0 libxcb-icccm4 libxcb-keysyms1"]
    libs["wayland"] = []  # the Wayland plugin loads: nothing to fix
    assert syscheck.problem({"WAYLAND_DISPLAY": "w", "DISPLAY": ":0"}) is None
    assert syscheck.problem({"QT_QPA_PLATFORM": "offscreen"}) is None


def test_the_editor_stops_with_the_line_instead_of_a_qt_abort(monkeypatch, capsys):
    from app import __main__ as entry

    monkeypatch.setattr(entry, "_qt_running", lambda: False)
    monkeypatch.setattr(
        syscheck,
        "problem",
        lambda: "Qt's xcb platform plugin needs …\n    sudo apt-get install libxcb-icccm4",
    )
    assert entry.main([]) == 1
    err = capsys.readouterr().err
    assert err.startswith("lsys-editor: Qt's xcb platform plugin") and "apt-get install libxcb-icccm4" in err
