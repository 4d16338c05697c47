"""Fuzz the readers -- SVG, ``.lsys``, CSS, path data -- for a bounded time.

Usage::

    python tests/fuzz/fuzz_svg.py --seconds 60 [--target svg|lsys|css|path|all] [--seed N] [--per-input 5]

Hypothesis generates inputs (random SVG trees with broken attributes, ``<use>`` graphs,
byte-mutated real files, plain junk; token soups for ``.lsys``, style sheets and path data), in
rounds of a few hundred examples with fresh seeds until the time budget is spent (``all`` takes
the targets in turn).  Every input must give a clean result or a one-line
:class:`~lsys_core.errors.LsysError` (see ``tests/robustness/oracles.py``) within ``--per-input``
seconds, under a 2 GiB address-space limit.  On the first failure the shrunk input is printed and
written to ``tests/fuzz/findings/`` (``TARGET-HASH.txt``: the report; ``TARGET-HASH.input``: the
input itself), and the exit status is 1.  Every ``.input`` file there is a regression test
(``tests/robustness/test_fuzz_corpus.py``): keep it once the bug is fixed.
"""

from __future__ import annotations

import argparse
import hashlib
import resource
import signal
import sys
import time
import traceback
import warnings
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from hypothesis import HealthCheck, Phase, given, seed, settings  # noqa: E402
from hypothesis.errors import HypothesisWarning  # noqa: E402

from tests.robustness.generators import css_texts, lsys_texts, path_texts, svg_bytes  # noqa: E402
from tests.robustness.oracles import (  # noqa: E402
    check_css_text,
    check_lsys_text,
    check_path_data,
    check_svg_import,
)

__all__ = ["main"]

FINDINGS = Path(__file__).resolve().parent / "findings"
MEMORY_LIMIT = 2 << 30
#: Each target: its input strategy and its oracle.
TARGETS = {
    "svg": (svg_bytes, check_svg_import),
    "lsys": (lsys_texts, check_lsys_text),
    "css": (css_texts, check_css_text),
    "path": (path_texts, check_path_data),
}
#: The last input that failed, by target (hypothesis shrinks: the last one is the smallest).
_LAST_FAILURE: dict[str, object] = {}


class SlowInput(Exception):
    """An input took longer than the per-input budget (a hang)."""


def _alarm(signum, frame) -> None:
    raise SlowInput("input took longer than the per-input time budget")


def _timed(target: str, check, per_input: float):
    """Wrap ``check`` so that one input may run at most ``per_input`` seconds; remember failures."""

    def run(value) -> None:
        signal.setitimer(signal.ITIMER_REAL, per_input)
        try:
            check(value)
        except BaseException:
            _LAST_FAILURE[target] = value
            raise
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)

    return run


def _round(target: str, rnd_seed: int, examples: int, per_input: float) -> None:
    """Run one hypothesis round of ``examples`` inputs; raise on the first (shrunk) failure."""
    make, check = TARGETS[target]
    strategy = make()
    run = _timed(target, check, per_input)

    @seed(rnd_seed)
    @settings(
        max_examples=examples,
        deadline=None,
        database=None,
        phases=[Phase.generate, Phase.shrink],
        suppress_health_check=list(HealthCheck),
        print_blob=True,
    )
    @given(strategy)
    def fuzz(value) -> None:
        run(value)

    fuzz()


def _failures(exc: BaseException) -> list[BaseException]:
    """Return the individual failures (hypothesis groups distinct failures in an ExceptionGroup)."""
    if isinstance(exc, BaseExceptionGroup):
        return [leaf for sub in exc.exceptions for leaf in _failures(sub)]
    return [exc]


def _report(target: str, exc: BaseException) -> None:
    """Print each failure with the input hypothesis reported and its last frame; save it to ``findings/``."""
    for failure in _failures(exc):
        notes = "\n".join(getattr(failure, "__notes__", []))
        tb = traceback.extract_tb(failure.__traceback__)
        where = f" at {tb[-1].filename}:{tb[-1].lineno}" if tb else ""
        head = f"{type(failure).__name__}: {failure}{where}"
        print(f"fuzz: {head}\n{notes}", file=sys.stderr)
        FINDINGS.mkdir(exist_ok=True)
        name = hashlib.sha256(notes.encode()).hexdigest()[:12]
        path = FINDINGS / f"{target}-{name}.txt"
        path.write_text(f"{head}\n{notes}\n", encoding="utf-8")
        value = _LAST_FAILURE.get(target)
        if value is not None:
            raw = value if isinstance(value, bytes) else str(value).encode("utf-8", "surrogatepass")
            path.with_suffix(".input").write_bytes(raw)
        print(f"fuzz: written to {path}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    """Fuzz until the time budget is spent or an input fails; return the exit status."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seconds", type=float, default=60.0, help="total time budget (default 60)")
    p.add_argument("--target", choices=[*TARGETS, "all"], default="all")
    p.add_argument("--seed", type=int, default=None, help="first round's seed (default: from the clock)")
    p.add_argument("--examples", type=int, default=300, help="inputs per round (default 300)")
    p.add_argument("--per-input", type=float, default=5.0, help="seconds one input may take (default 5)")
    args = p.parse_args(argv)

    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))
    signal.signal(signal.SIGALRM, _alarm)
    warnings.simplefilter("ignore", HypothesisWarning)
    warnings.simplefilter("error", RuntimeWarning)  # numpy noise on stderr counts as a finding
    targets = list(TARGETS) if args.target == "all" else [args.target]
    base = args.seed if args.seed is not None else int(time.time())
    deadline = time.monotonic() + args.seconds
    rounds = inputs = 0
    while time.monotonic() < deadline:
        target = targets[rounds % len(targets)]
        rnd_seed = base + rounds
        try:
            _round(target, rnd_seed, args.examples, args.per_input)
        except Exception as exc:  # a finding: report it and stop
            print(f"fuzz: FAILURE in {target} round with seed {rnd_seed}", file=sys.stderr)
            _report(target, exc)
            return 1
        rounds += 1
        inputs += args.examples
        print(f"fuzz: round {rounds} ({target}, seed {rnd_seed}) ok; {inputs} inputs", file=sys.stderr)
    print(f"fuzz: no failures in {inputs} inputs ({rounds} rounds, {args.seconds:g} s)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
