"""numpy sorts with AVX2 where its AVX-512 sort is slow (lsys_core.cpu), and only there."""

from __future__ import annotations

import os
import platform
import subprocess
import sys

import pytest

from lsys_core.cpu import (
    FEATURES,
    HUGEPAGE,
    VARIABLE,
    in_virtual_machine,
    numpy_version,
    prefer_fast_sort,
    prefer_small_pages,
    slow_compress_store,
)

ZEN4_LINUX = (
    "processor\t: 0\nvendor_id\t: AuthenticAMD\ncpu family\t: 25\nmodel\t\t: 17\nflags\t\t: avx512f\n"
)
ZEN5_LINUX = ZEN4_LINUX.replace(": 25", ": 26")
INTEL_LINUX = "processor\t: 0\nvendor_id\t: GenuineIntel\ncpu family\t: 6\nmodel\t\t: 143\n"
ZEN4_WINDOWS = "AMD64 Family 25 Model 17 Stepping 1, AuthenticAMD"
ZEN4_VM = ZEN4_LINUX.replace("flags\t\t: avx512f", "flags\t\t: fpu avx512f hypervisor vmmcall")


@pytest.mark.parametrize(
    ("description", "slow"),
    [
        (ZEN4_LINUX, True),
        (ZEN4_WINDOWS, True),
        (ZEN5_LINUX, False),
        (INTEL_LINUX, False),
        ("Intel64 Family 6 Model 143 Stepping 8, GenuineIntel", False),
        ("AMD64 Family 23 Model 49 Stepping 0, AuthenticAMD", False),
        ("", False),
    ],
)
def test_slow_compress_store_is_amd_family_19h(description: str, slow: bool) -> None:
    assert slow_compress_store(description) is slow


def test_sets_the_variable_on_zen4_with_numpy_2_4() -> None:
    env: dict[str, str] = {}
    assert prefer_fast_sort(env, ZEN4_LINUX, (2, 4))
    assert env == {VARIABLE: FEATURES}


@pytest.mark.parametrize(
    ("env", "processor", "version"),
    [
        ({VARIABLE: ""}, ZEN4_LINUX, (2, 4)),  # the user's choice, even empty
        ({VARIABLE: "AVX512_SPR"}, ZEN4_LINUX, (2, 4)),
        ({}, INTEL_LINUX, (2, 4)),
        ({}, ZEN5_LINUX, (3, 0)),
        ({}, ZEN4_LINUX, (2, 3)),  # other feature names
        ({}, ZEN4_LINUX, (1, 26)),
    ],
)
def test_leaves_the_environment_alone_elsewhere(env, processor, version) -> None:
    before = dict(env)
    assert not prefer_fast_sort(env, processor, version)
    assert env == before


def test_reads_the_installed_numpy_version_without_importing_it() -> None:
    import numpy as np

    major, minor = (int(p) for p in np.__version__.split(".")[:2])
    assert numpy_version() == (major, minor)


@pytest.mark.skipif(
    platform.machine().lower() not in ("x86_64", "amd64") or (numpy_version() or (0, 0)) < (2, 4),
    reason="numpy's x86 feature names of numpy >= 2.4",
)
def test_numpy_accepts_the_features_and_turns_avx512_off() -> None:
    """With the variable set, numpy imports without a warning (every name is one of its own)
    and its AVX-512 groups are off."""
    code = (
        "from numpy._core._multiarray_umath import __cpu_features__ as f; "
        "print(f.get('X86_V4'), f.get('AVX512_ICL'), f.get('AVX512_SPR'))"
    )
    env = dict(os.environ, **{VARIABLE: FEATURES})
    out = subprocess.run(
        [sys.executable, "-W", "error::ImportWarning", "-c", code],
        env=env,
        capture_output=True,
        text=True,
        check=True,
    )
    assert out.stdout.split() == ["False", "False", "False"]
    assert out.stderr == ""


def test_lsys_sets_them_before_numpy_is_imported() -> None:
    """The ``lsys`` program (``run``) sets both variables on a Zen 4 virtual machine before numpy loads."""
    code = (
        "import os, sys, lsys_core.cpu as c, lsys_core.cli as cli\n"
        f"c._processor = lambda: {ZEN4_VM!r}\n"
        "c.numpy_version = lambda: (2, 4)\n"
        "assert 'numpy' not in sys.modules\n"
        "sys.argv = ['lsys', '--version']\n"
        "try:\n"
        "    cli.run()\n"
        "except SystemExit:\n"
        "    pass\n"
        "print(os.environ.get(c.VARIABLE), os.environ.get(c.HUGEPAGE))\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in (VARIABLE, HUGEPAGE)}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.splitlines()[-1] == f"{FEATURES} 0"


@pytest.mark.parametrize(
    ("description", "vm"),
    [
        (ZEN4_VM, True),
        (ZEN4_LINUX, False),
        (INTEL_LINUX, False),  # no flags line
        (ZEN4_LINUX.replace("avx512f", "avx512f hypervisorx"), False),  # whole flags only
        (ZEN4_WINDOWS, False),
    ],
)
def test_in_virtual_machine_reads_the_hypervisor_flag(description: str, vm: bool) -> None:
    assert in_virtual_machine(description) is vm


def test_small_pages_in_a_virtual_machine_only_and_never_over_the_user() -> None:
    env: dict[str, str] = {}
    assert prefer_small_pages(env, ZEN4_VM)
    assert env == {HUGEPAGE: "0"}
    for env, processor in (({HUGEPAGE: "1"}, ZEN4_VM), ({HUGEPAGE: ""}, ZEN4_VM), ({}, ZEN4_LINUX)):
        before = dict(env)
        assert not prefer_small_pages(env, processor)
        assert env == before


def test_numpy_reads_the_huge_page_variable() -> None:
    import numpy as np

    if not hasattr(np._core.multiarray, "_get_madvise_hugepage"):
        pytest.skip("this numpy does not say whether it asks for huge pages")
    code = "import numpy as np; print(np._core.multiarray._get_madvise_hugepage())"
    env = dict(os.environ, **{HUGEPAGE: "0"})
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
