"""Every input the fuzzer found (``tests/fuzz/findings/*.input``) stays fixed: a regression test each."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.robustness.oracles import check_css_text, check_lsys_text, check_path_data, check_svg_import

FINDINGS = Path(__file__).resolve().parents[1] / "fuzz" / "findings"
CHECKS = {"svg": check_svg_import, "lsys": check_lsys_text, "css": check_css_text, "path": check_path_data}
CASES = sorted(FINDINGS.glob("*.input")) if FINDINGS.is_dir() else []


@pytest.mark.filterwarnings("error::RuntimeWarning")  # as the fuzzer counts them: noise on stderr
@pytest.mark.parametrize("path", CASES, ids=[p.stem for p in CASES])
def test_fuzz_finding_stays_fixed(path: Path) -> None:
    target = path.stem.split("-", 1)[0]
    data = path.read_bytes()
    check = CHECKS[target]
    check(data if target == "svg" else data.decode("utf-8", "surrogatepass"))


def test_every_target_has_an_oracle() -> None:
    assert {p.stem.split("-", 1)[0] for p in CASES} <= set(CHECKS)
