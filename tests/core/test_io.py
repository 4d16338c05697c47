"""Tests of atomic file writing."""

from __future__ import annotations

import os
import stat

import pytest

from lsys_core.errors import LsysError
from lsys_core.io import write as lio
from lsys_core.io import write_atomic


def _leftovers(directory) -> list[str]:
    return [p.name for p in directory.iterdir() if p.name.endswith(".tmp")]


def test_writes_text_and_bytes(tmp_path):
    target = tmp_path / "out.svg"
    write_atomic(target, "héllo\n")
    assert target.read_bytes() == "héllo\n".encode()
    write_atomic(str(target), b"\x00\x01binary")
    assert target.read_bytes() == b"\x00\x01binary"
    assert _leftovers(tmp_path) == []


def test_failed_replace_leaves_existing_file_unchanged(tmp_path, monkeypatch):
    target = tmp_path / "drawing.svg"
    target.write_bytes(b"original content")

    def broken_replace(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(lio.os, "replace", broken_replace)
    with pytest.raises(LsysError) as info:
        write_atomic(target, "new content that must not appear")
    message = str(info.value)
    assert message.startswith(f"cannot write {target}")
    assert "No space left on device" in message
    assert "\n" not in message
    assert target.read_bytes() == b"original content"
    assert _leftovers(tmp_path) == []


def test_failed_write_removes_temp_file(tmp_path, monkeypatch):
    target = tmp_path / "x.txt"
    target.write_text("keep")
    real_fsync = os.fsync

    def failing_fsync(fd):
        raise OSError(5, "Input/output error")

    monkeypatch.setattr(lio.os, "fsync", failing_fsync)
    with pytest.raises(LsysError, match="Input/output error"):
        write_atomic(target, "lost")
    monkeypatch.setattr(lio.os, "fsync", real_fsync)
    assert target.read_text() == "keep"
    assert _leftovers(tmp_path) == []


def test_missing_directory_is_an_lsys_error(tmp_path):
    with pytest.raises(LsysError, match="cannot write"):
        write_atomic(tmp_path / "no" / "such" / "dir" / "f.svg", "x")


def test_target_that_is_a_directory_is_left_alone(tmp_path):
    target = tmp_path / "folder"
    target.mkdir()
    (target / "inside.txt").write_text("data")
    with pytest.raises(LsysError, match="cannot write"):
        write_atomic(target, "x")
    assert (target / "inside.txt").read_text() == "data"
    assert _leftovers(tmp_path) == []


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="needs POSIX permissions as non-root")
def test_read_only_directory(tmp_path):
    target = tmp_path / "f.txt"
    target.write_text("before")
    tmp_path.chmod(stat.S_IRUSR | stat.S_IXUSR)
    try:
        with pytest.raises(LsysError, match="cannot write"):
            write_atomic(target, "after")
    finally:
        tmp_path.chmod(stat.S_IRWXU)
    assert target.read_text() == "before"


@pytest.mark.skipif(os.name != "posix", reason="POSIX file modes")
def test_keeps_permissions_of_replaced_file(tmp_path):
    target = tmp_path / "f.txt"
    target.write_text("before")
    target.chmod(0o640)
    write_atomic(target, "after")
    assert target.read_text() == "after"
    assert stat.S_IMODE(target.stat().st_mode) == 0o640
