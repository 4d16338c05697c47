"""Bounded reading: every reader's size limit at limit - 1 (works) and limit + 1 (one clean error)."""

from __future__ import annotations

import io

import pytest

from lsys_core.errors import LimitError, LsysError
from lsys_core.io import MAX_TEXT_BYTES, read_bytes, read_text
from lsys_core.svg.parse import DEFAULT_MAX_BYTES


def sparse(path, size: int):
    with open(path, "wb") as fh:
        fh.truncate(size)
    return path


@pytest.mark.parametrize("kind", ["file", "stream"])
def test_text_limit(tmp_path, kind) -> None:
    def source(n: int):
        if kind == "stream":
            return io.BytesIO(b"a" * n)
        (tmp_path / "r.lsys").write_bytes(b"a" * n)
        return tmp_path / "r.lsys"

    assert len(read_text(source(MAX_TEXT_BYTES - 1))) == MAX_TEXT_BYTES - 1
    assert len(read_text(source(MAX_TEXT_BYTES))) == MAX_TEXT_BYTES
    with pytest.raises(LimitError, match=r"too large .*20,000,000"):
        read_text(source(MAX_TEXT_BYTES + 1))


def test_svg_byte_limit_from_the_file_size(tmp_path) -> None:
    assert len(read_bytes(sparse(tmp_path / "a.svg", DEFAULT_MAX_BYTES - 1), limit=DEFAULT_MAX_BYTES)) == (
        DEFAULT_MAX_BYTES - 1
    )
    with pytest.raises(LimitError, match=r"\(50,000,001 bytes; the limit is 50,000,000\)"):
        read_bytes(sparse(tmp_path / "b.svg", DEFAULT_MAX_BYTES + 1), limit=DEFAULT_MAX_BYTES)


def test_stream_limit_is_checked_while_reading() -> None:
    assert read_bytes(io.BytesIO(b"x" * 999), limit=1000) == b"x" * 999
    with pytest.raises(LimitError, match="more than 1,000 bytes"):
        read_bytes(io.BytesIO(b"x" * 1001), limit=1000)


def test_text_errors_are_located() -> None:
    with pytest.raises(LsysError, match=r"^r:2:3: not UTF-8 text \(byte 0xff\)$"):
        read_text(io.BytesIO(b"ok\nab\xffc"), name="r")
    with pytest.raises(LsysError, match=r"^r:1:4: unexpected character NUL"):
        read_text(io.BytesIO(b"abc\x00"), name="r")
    assert read_text(io.BytesIO("\ufeffé\n".encode()), name="r") == "é\n"


def test_unreadable_input_is_one_line(tmp_path) -> None:
    with pytest.raises(LsysError, match=r"^cannot read .*missing\.lsys: No such file or directory$"):
        read_text(tmp_path / "missing.lsys")
    with pytest.raises(LsysError, match="Is a directory"):
        read_bytes(tmp_path, limit=10)
