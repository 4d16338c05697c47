"""Values remembered by object identity (shared styles, a cached level's candidates)."""

from __future__ import annotations

from lsys_core.memo import IdentityMemo


def test_computes_once_per_object_not_per_equal_value() -> None:
    calls: list[dict] = []
    memo: IdentityMemo[dict, int] = IdentityMemo()
    a, b = {"fill": "red"}, {"fill": "red"}
    for obj in (a, a, b, a):
        memo.get(obj, lambda o: calls.append(o) or len(calls))
    assert calls == [a, b]  # equal but distinct objects are computed each
    assert memo.get(a, lambda o: -1) == 1 and memo.get(b, lambda o: -1) == 2


def test_a_full_memo_starts_again() -> None:
    memo: IdentityMemo[object, int] = IdentityMemo(size=2)
    objs = [object() for _ in range(3)]
    for i, o in enumerate(objs):
        memo.get(o, lambda _o, i=i: i)
    assert memo.get(objs[2], lambda _o: -1) == 2  # kept: stored after the clear
    assert memo.get(objs[0], lambda _o: -1) == -1  # dropped by the clear
