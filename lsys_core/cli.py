"""The ``lsys`` command: infer, symmetrize, derive and inspect L-systems without a GUI.

Every failure prints one line ``lsys: error: …`` on stderr and exits 1 (2 for usage
errors, 130 when interrupted, 70 for an internal error, i.e. a bug: set ``LSYS_DEBUG=1``
to see its traceback).  Outputs are checked before any work starts, computed in memory,
and written together atomically: a failed run writes nothing and leaves existing files
byte for byte untouched.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from collections.abc import Sequence
from pathlib import Path

from lsys_core import __version__
from lsys_core.errors import LsysError

__all__ = ["main"]

#: Largest accepted ``--limit``: beyond it a derivation's arrays and SVG text outgrow memory anyway.
MAX_LIMIT = 100_000_000


class _Progress:
    """Stage and percentage on stderr when it is a terminal (``--quiet`` silences it)."""

    def __init__(self, enabled: bool) -> None:
        self.enabled = enabled
        self.last = ""

    def __call__(self, stage: str, fraction: float) -> None:
        if not self.enabled:
            return
        text = f"\r{stage:<12} {fraction * 100:5.1f}%"
        if text != self.last:
            sys.stderr.write(text)
            sys.stderr.flush()
            self.last = text

    def close(self) -> None:
        if self.enabled and self.last:
            sys.stderr.write("\r" + " " * len(self.last) + "\r")
            sys.stderr.flush()


def _weights(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("inference settings")
    g.add_argument("--wn", type=float, help="weight of repetition count n, in [0, 1]")
    g.add_argument("--wh", type=float, help="weight of proximity h, in [0, 1]")
    g.add_argument("--wphi", type=float, help="weight of similarity φ, in [0, 1]")
    g.add_argument("--wl", type=float, help="weight of sequence length l, in [0, 1]")
    g.add_argument(
        "--similarity", type=float, help="similarity threshold φ for shared terminals (default 0.6)"
    )
    g.add_argument("--tolerance", type=float, help="factor on the clustering bandwidths (default 1)")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="lsys",
        description="Turn vector art into an editable parametric L-system, and back.",
    )
    p.add_argument("--version", action="version", version=f"lsys {__version__}")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress or warnings on stderr")
    p.add_argument("-v", "--verbose", action="store_true", help="print stage timings and the rule log")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    inf = sub.add_parser("infer", help="infer rules from an SVG")
    inf.add_argument("input", help="input SVG")
    inf.add_argument("-o", "--output", help="write the rules (.lsys); default: print them")
    inf.add_argument("--svg", help="write the derivation of the inferred rules as SVG")
    inf.add_argument("--png", help="write the derivation as PNG")
    inf.add_argument(
        "--report", help="write a JSON report (elements, symbols, rules, axiom, seconds, stages)"
    )
    _weights(inf)

    sym = sub.add_parser("symmetrize", help="regularise a jittered pattern through relaxed inference")
    sym.add_argument("input", help="input SVG")
    sym.add_argument("-o", "--output", required=True, help="output SVG")
    sym.add_argument("--rules", help="also write the rules (.lsys)")
    _weights(sym)

    der = sub.add_parser("derive", help="derive rules into SVG/PNG")
    der.add_argument("rules", help="rules file (.lsys)")
    der.add_argument("-o", "--output", required=True, help="output SVG")
    der.add_argument("--png", help="also write a PNG")
    der.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="set a rule parameter (see `lsys params`); repeatable",
    )
    der.add_argument(
        "--randomize",
        metavar="angle=DEG,distance=FRAC,scale=FRAC",
        help="perturb every rule application by up to these amounts",
    )
    der.add_argument("--seed", type=int, default=0, help="random seed for --randomize (default 0)")
    der.add_argument("--limit", type=int, default=None, help="maximum number of elements (default 1,000,000)")

    par = sub.add_parser("params", help="list the numeric parameters of a rules file")
    par.add_argument("rules", help="rules file (.lsys)")
    return p


def _settings(args: argparse.Namespace):
    from lsys_core.pipeline import InferenceSettings

    kw = {k: getattr(args, k) for k in ("wn", "wh", "wphi", "wl", "similarity", "tolerance")}
    return InferenceSettings(**{k: v for k, v in kw.items() if v is not None})


def _read_text(path: str) -> str:
    try:
        data = Path(path).read_bytes()
    except OSError as e:
        raise LsysError(f"cannot read {path}: {e.strerror or e}") from None
    if len(data) > 20_000_000:
        raise LsysError(f"{path} is too large for a rules file ({len(data):,} bytes)")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise LsysError(f"{path} is not UTF-8 text") from None


def _load_rules(path: str):
    from lsys_core.errors import GrammarSyntaxError
    from lsys_core.grammar import parse_grammar

    try:
        return parse_grammar(_read_text(path), check_paths=True)
    except GrammarSyntaxError as e:
        raise LsysError(f"{path}:{e}") from None


def _check_outputs(paths: list[str | None]) -> None:
    """Fail fast, before any work, on outputs that cannot be written (missing folder, a folder, twice)."""
    seen: dict[str, str] = {}
    for path in filter(None, paths):
        key = os.path.normcase(os.path.abspath(path))
        if key in seen:
            raise LsysError(f"cannot write {path}: the same file is given twice as an output")
        seen[key] = path
        target = Path(path)
        parent = target.parent if str(target.parent) else Path(".")
        if target.is_dir():
            raise LsysError(f"cannot write {path}: Is a directory")
        if not parent.is_dir():
            reason = "Not a directory" if parent.exists() else "No such file or directory"
            raise LsysError(f"cannot write {path}: {reason}")


def _derive(grammar, **options):
    """Derive quietly (numpy overflow warnings are not for the user; non-finite poses are checked on output)."""
    import numpy as np

    from lsys_core.derive.derivation import derive

    with np.errstate(all="ignore"):
        return derive(grammar, **options)


def _parse_randomize(text: str | None, seed: int):
    from lsys_core.derive.derivation import Randomize

    if not text:
        return None
    amounts = {"angle": 0.0, "distance": 0.0, "scale": 0.0}
    for part in filter(None, text.split(",")):
        key, sep, val = part.partition("=")
        key = key.strip()
        if not sep or key not in amounts:
            raise LsysError(f"--randomize: expected angle=DEG,distance=FRAC,scale=FRAC, got {part!r}")
        try:
            v = float(val)
        except ValueError:
            raise LsysError(f"--randomize: {key} must be a number, got {val!r}") from None
        if not (0.0 <= v < float("inf")):
            raise LsysError(f"--randomize: {key} must be a finite number >= 0, got {val!r}")
        amounts[key] = v
    return Randomize(seed=seed, **amounts)


def _parse_sets(items: list[str]) -> dict[str, float]:
    out: dict[str, float] = {}
    for item in items:
        key, sep, val = item.partition("=")
        if not sep or not key.strip():
            raise LsysError(f"--set: expected NAME=VALUE, got {item!r}")
        try:
            out[key.strip()] = float(val)
        except ValueError:
            raise LsysError(f"--set {key.strip()}: value must be a number, got {val!r}") from None
    return out


def _drawing_outputs(drawing, svg: str | None, png: str | None) -> list[tuple[str, str | bytes]]:
    """Return the SVG and PNG files of a drawing as ``(path, content)``, computed in memory."""
    import numpy as np

    out: list[tuple[str, str | bytes]] = []
    if not (svg or png):
        return out
    from lsys_core.render.svg import check_finite, drawing_to_svg

    check_finite(drawing)  # an overflowing grammar is an error, not an empty or broken picture
    with np.errstate(all="ignore"):
        if svg:
            out.append((svg, drawing_to_svg(drawing)))
        if png:
            from lsys_core.render.raster import encode_png

            try:
                out.append((png, encode_png(drawing)))
            except LsysError as e:
                raise LsysError(f"cannot write {png}: {e}") from None
    return out


def _commit(files: list[tuple[str, str | bytes]]) -> None:
    """Write all output files at once: all of them or none."""
    from lsys_core.io import write_files_atomic

    if files:
        write_files_atomic(files)


def _infer_report(result, scene, drawing) -> dict:
    from lsys_core.grammar import format_grammar

    g = result.grammar
    text = format_grammar(g)
    rules = [line for line in text.splitlines() if "->" in line and not line.startswith("axiom")]
    axiom = next(
        (line.split(":", 1)[1].strip() for line in text.splitlines() if line.startswith("axiom:")), ""
    )
    return {
        "elements": len(scene.elements),
        "symbols": len(g.terminals) + len(g.rules),
        "terminals": len(g.terminals),
        "rules": rules,
        "axiom": axiom,
        "derived_elements": len(drawing),
        "seconds": round(result.seconds, 4),
        "stages": {k: round(v, 4) for k, v in result.stages.items()},
        "warnings": list(scene.warnings),
        "log": list(result.log),
    }


def _cmd_infer(args, progress: _Progress, symmetrize: bool = False) -> int:
    from lsys_core.grammar import format_grammar
    from lsys_core.pipeline import infer
    from lsys_core.pipeline import symmetrize as sym_fn
    from lsys_core.svg.parse import load_svg

    if symmetrize:
        _check_outputs([args.output, args.rules])
    else:
        _check_outputs([args.output, args.svg, args.png, args.report])
    t0 = time.perf_counter()
    scene = load_svg(args.input)
    t_import = time.perf_counter() - t0
    if scene.warnings and not args.quiet:
        for w in scene.warnings:
            print(f"lsys: warning: {w}", file=sys.stderr)
    settings = _settings(args)
    fn = sym_fn if symmetrize else infer
    result = fn(scene, settings, progress=progress)
    t = time.perf_counter()
    drawing = _derive(result.grammar)
    t_derive = time.perf_counter() - t
    result.stages["svg_import"] = t_import
    result.stages["derivation"] = t_derive
    progress.close()
    text = format_grammar(result.grammar)
    files: list[tuple[str, str | bytes]] = []
    if symmetrize:
        files += _drawing_outputs(drawing, args.output, None)
        if args.rules:
            files.append((args.rules, text))
    else:
        if args.output:
            files.append((args.output, text))
        files += _drawing_outputs(drawing, args.svg, args.png)
        if args.report:
            rep = _infer_report(result, scene, drawing)
            rep["seconds"] = round(time.perf_counter() - t0, 4)
            files.append((args.report, json.dumps(rep, indent=1, ensure_ascii=False) + "\n"))
    _commit(files)
    if not symmetrize and not args.output and not args.report:
        sys.stdout.write(text)
    if args.verbose:
        for k, v in result.stages.items():
            print(f"lsys: {k:<12} {v * 1000:8.1f} ms", file=sys.stderr)
        for line in result.log:
            print(f"lsys: {line}", file=sys.stderr)
    return 0


def _cmd_derive(args) -> int:
    from lsys_core.derive.derivation import DEFAULT_LIMIT
    from lsys_core.grammar import set_params

    _check_outputs([args.output, args.png])
    limit = DEFAULT_LIMIT if args.limit is None else args.limit
    if not 1 <= limit <= MAX_LIMIT:
        raise LsysError(f"--limit must be between 1 and {MAX_LIMIT:,}, got {limit:,}")
    if args.seed < 0:
        raise LsysError(f"--seed must be a whole number >= 0, got {args.seed}")
    g = _load_rules(args.rules)
    sets = _parse_sets(args.set)
    if sets:
        g = set_params(g, sets)
    rnd = _parse_randomize(args.randomize, args.seed)
    drawing = _derive(g, limit=limit, randomize=rnd)
    _commit(_drawing_outputs(drawing, args.output, args.png))
    if args.verbose:
        print(f"lsys: derived {len(drawing):,} elements", file=sys.stderr)
    return 0


def _cmd_params(args) -> int:
    from lsys_core.grammar import list_params

    g = _load_rules(args.rules)
    for p in list_params(g):
        print(f"{p.key:<16} {p.value:>14.6g}  {p.kind:<15} {p.label}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Run the ``lsys`` command line; returns the exit status."""
    parser = _parser()
    args = parser.parse_args(argv)
    progress = _Progress(enabled=not args.quiet and sys.stderr.isatty())
    try:
        if args.command == "infer":
            return _cmd_infer(args, progress)
        if args.command == "symmetrize":
            return _cmd_infer(args, progress, symmetrize=True)
        if args.command == "derive":
            return _cmd_derive(args)
        return _cmd_params(args)
    except LsysError as e:
        progress.close()
        print(f"lsys: error: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        progress.close()
        print("lsys: error: interrupted", file=sys.stderr)
        return 130
    except MemoryError:
        progress.close()
        print("lsys: error: out of memory", file=sys.stderr)
        return 1
    except RecursionError:
        progress.close()
        print("lsys: error: the input is nested too deeply", file=sys.stderr)
        return 1
    except Exception as e:  # a bug: one line for the user, the traceback on request
        progress.close()
        if os.environ.get("LSYS_DEBUG"):
            raise
        detail = " ".join(str(e).split())[:200]
        print(
            f"lsys: error: internal error ({type(e).__name__}: {detail}); "
            "please report this bug (LSYS_DEBUG=1 shows the traceback)",
            file=sys.stderr,
        )
        return 70


if __name__ == "__main__":
    sys.exit(main())
