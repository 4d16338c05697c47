"""The editor reads .lsys files with the library's bounded reader, as the lsys command does."""

from __future__ import annotations

import os

import pytest

from app import core
from lsys_core.errors import LsysError


def test_line_ends_become_unix_and_a_bom_is_dropped(tmp_path):
    path = tmp_path / "r.lsys"
    path.write_bytes(b'\xef\xbb\xbflsys 1\r\naxiom: A\rterminal A "M0 0 L1 0"\n')
    assert core.read_text(str(path)) == 'lsys 1\naxiom: A\nterminal A "M0 0 L1 0"\n'


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (b"lsys 1\naxiom: \xff\n", r"r\.lsys:2:8: not UTF-8 text"),
        (b"lsys 1\n\x00\x00", r"r\.lsys:2:1: unexpected character NUL"),
    ],
)
def test_binary_or_bad_utf8_is_one_line_naming_the_place(tmp_path, data, message):
    path = tmp_path / "r.lsys"
    path.write_bytes(data)
    with pytest.raises(LsysError, match=message):
        core.read_text(str(path))


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
def test_an_endless_device_stops_at_the_first_chunk():
    with pytest.raises(LsysError, match="NUL"):
        core.read_text("/dev/zero")
