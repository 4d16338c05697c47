"""Cancel tokens: checks raise once cancelled; a token made to share the GIL naps at its checks."""

from __future__ import annotations

import pytest

import lsys_core.cancel as cancel
from lsys_core.errors import Cancelled


def test_check_raises_only_after_cancel():
    token = cancel.CancelToken()
    token.check()
    cancel.check(None)
    token.cancel()
    assert token.cancelled
    with pytest.raises(Cancelled):
        cancel.check(token)


@pytest.mark.parametrize("share", [False, True])
def test_a_token_that_shares_the_gil_naps_at_its_checks(monkeypatch, share):
    naps: list[float] = []
    monkeypatch.setattr(cancel, "SHARE_EVERY", 0.0)  # every check is due
    monkeypatch.setattr(cancel.time, "sleep", naps.append)
    token = cancel.CancelToken(share_gil=share)
    for _ in range(3):
        token.check()
    assert naps == ([cancel.SHARE_NAP] * 3 if share else [])
