"""The subcommands of ``lsys``: each reads its inputs, computes every output in memory, then writes them."""

from __future__ import annotations

import argparse
import contextlib
import gc
import json
import math
import sys
import time
from collections.abc import Callable
from typing import BinaryIO

from lsys_core.cli.args import STDIO
from lsys_core.errors import LsysError
from lsys_core.io import Target, check_outputs, read_bytes, read_text, write_files_atomic
from lsys_core.quoting import quote_name

__all__ = ["MAX_LIMIT", "Progress", "run_command"]

#: Largest accepted ``--limit``: beyond it a derivation's arrays and SVG text outgrow memory anyway.
MAX_LIMIT = 100_000_000
#: Stage entries of an inference result that are not durations (printed and reported apart).
_NOT_TIMINGS = ("reproduction_error",)

Say = Callable[[str], None]
Files = list[tuple[Target, str | bytes]]


class Progress:
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
            self.last = ""


# ---------------------------------------------------------------------------
# Files: '-' is standard input or output


def _name(path: str) -> str:
    """How a file given on the command line is called in messages."""
    return "standard input" if path == STDIO else quote_name(path)


def _source(path: str) -> str | BinaryIO:
    return sys.stdin.buffer if path == STDIO else path


def _stdout() -> BinaryIO:
    sys.stdout.flush()  # text printed before goes first
    return sys.stdout.buffer


def _target(path: str) -> Target:
    return _stdout() if path == STDIO else path


def _check(outputs: list[str | None], inputs: list[str]) -> None:
    """Refuse unusable outputs before any work (see :func:`lsys_core.io.check_outputs`)."""
    check_outputs(
        [None if p is None else (sys.stdout.buffer if p == STDIO else p) for p in outputs],
        [p for p in inputs if p != STDIO],
    )


def _commit(files: Files) -> None:
    """Write all outputs at once: all of them or no file changed."""
    if files:
        write_files_atomic([(_target(t) if isinstance(t, str) else t, d) for t, d in files])


def _read_svg(path: str):
    """Return the scene of an input SVG and its head (title, description, root attributes)."""
    from lsys_core.svg.head import read_head
    from lsys_core.svg.parse import DEFAULT_MAX_BYTES, parse_svg

    name = _name(path)
    data = read_bytes(_source(path), limit=DEFAULT_MAX_BYTES, name=name)
    scene = parse_svg(data, max_bytes=DEFAULT_MAX_BYTES, name=name, allow_empty=True)
    return scene, read_head(data)


def _empty_grammar(scene):
    """The rules of a document that draws nothing: its canvas, and an axiom rewritten to ε."""
    from lsys_core.grammar.model import Case, Grammar, Rule, Symbol

    return Grammar((), (Rule("Z", False, (Case(None, ()),)),), (Symbol("Z"),), scene.viewbox, scene.size)


def _infer_nothing(args, scene, head, outputs: list, symmetrize: bool) -> int:
    """Write the empty rules (and their empty drawing) of a document that draws nothing."""
    from lsys_core.grammar import format_grammar

    grammar = _empty_grammar(scene)
    text = format_grammar(grammar)
    drawing = _derive(grammar)

    def report() -> dict:
        rep = {"elements": 0, "symbols": 1, "terminals": 0, "rules": ["Z -> ε"], "axiom": "Z"}
        rep.update(derived_elements=len(drawing), warnings=list(scene.warnings))
        return rep

    _commit(_infer_files(args, text, drawing, report, outputs, symmetrize, head))
    return 0


def _infer_files(args, text: str, drawing, report, outputs: list, symmetrize: bool, head) -> Files:
    """What ``infer`` (or ``symmetrize``) writes: rules, drawings and the report (``report()``)."""
    files: Files = []
    if symmetrize:
        files += _drawing_outputs(drawing, args.output, None, {}, flat=args.flat, head=head)
        if args.rules:
            files.append((args.rules, text))
        return files
    if args.output:
        files.append((args.output, text))
    png = getattr(args, "png", None)
    files += _drawing_outputs(drawing, args.svg, png, _png_options(args), flat=args.flat, head=head)
    if args.report:
        files.append((args.report, json.dumps(report(), indent=1, ensure_ascii=False) + "\n"))
    if not args.output and not args.report and STDIO not in outputs:
        files.append((STDIO, text))
    return files


def _load_rules(path: str):
    from lsys_core.errors import GrammarSyntaxError
    from lsys_core.grammar import parse_grammar

    name = _name(path)
    try:
        return parse_grammar(read_text(_source(path), name=name), check_paths=True)
    except GrammarSyntaxError as e:
        raise LsysError(f"{name}:{e}") from None


# ---------------------------------------------------------------------------
# Options


def _settings(args: argparse.Namespace):
    from lsys_core.parallel import jobs, set_jobs
    from lsys_core.pipeline import InferenceSettings
    from lsys_core.settings import SETTINGS

    set_jobs(getattr(args, "jobs", None))
    jobs()  # a bad LSYS_JOBS is reported before any work

    kw = {s.name: getattr(args, s.name) for s in SETTINGS}
    kw["deviation"] = getattr(args, "deviation", None)
    return InferenceSettings(**{k: v for k, v in kw.items() if v is not None}).validated()


def _png_options(args: argparse.Namespace) -> dict:
    """Check the PNG options before any work; return the keyword arguments of ``encode_png``."""
    if not getattr(args, "png", None):
        return {}
    # imported here: the renderer (skia) is loaded only by commands that write a PNG
    from lsys_core.render.raster import MAX_SIDE
    from lsys_core.render.units import parse_color

    if not (math.isfinite(args.dpi) and 1.0 <= args.dpi <= 10_000.0):
        raise LsysError(f"--dpi must be between 1 and 10,000, got {args.dpi:g}")
    for option in ("width", "height"):
        value = getattr(args, option)
        if value is not None and not 1 <= value <= MAX_SIDE:
            raise LsysError(f"--{option} must be between 1 and {MAX_SIDE:,} pixels, got {value:,}")
    try:
        background = parse_color(args.background)
    except LsysError as e:
        raise LsysError(f"--background: {e}") from None
    return {"width": args.width, "height": args.height, "dpi": args.dpi, "background": background}


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
    return Randomize(amounts["angle"], amounts["distance"], amounts["scale"], seed)


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


# ---------------------------------------------------------------------------
# Computing outputs


def _derive(grammar, **options):
    """Derive quietly (numpy overflow warnings are not for the user; non-finite poses are checked on output)."""
    import numpy as np

    from lsys_core.derive.derivation import derive

    with np.errstate(all="ignore"):
        return derive(grammar, **options)


def _drawing_outputs(
    drawing, svg: str | None, png: str | None, png_options: dict, *, flat: bool = False, head=None
) -> Files:
    """Return the SVG and PNG files of a drawing as ``(target, content)``, computed in memory.

    The SVG is structured (shapes in ``<defs>``, ``<use>`` instances, a group per rule call),
    or with ``flat`` one baked ``<path>`` per instance.
    """
    import numpy as np

    out: Files = []
    if not (svg or png):
        return out
    from lsys_core.render.svg import check_finite, drawing_to_svg

    check_finite(drawing)  # an overflowing grammar is an error, not an empty or broken picture
    with np.errstate(all="ignore"):
        if svg:
            if flat:
                out.append((svg, drawing_to_svg(drawing)))
            else:
                from lsys_core.render.structured import drawing_to_structured_svg

                out.append((svg, drawing_to_structured_svg(drawing, head=head)))
        if png:
            from lsys_core.render.raster import encode_png

            try:
                out.append((png, encode_png(drawing, **png_options)))
            except LsysError as e:
                raise LsysError(
                    f"cannot write {_name(png) if png != STDIO else 'standard output'}: {e}"
                ) from None
    return out


def _timings(result) -> dict[str, float]:
    return {k: v for k, v in result.stages.items() if k not in _NOT_TIMINGS}


def _summary(result, scene) -> str:
    """One line: elements, productions, how much repetition explains, deviation and description length."""
    before, after = result.description_bits
    return (
        f"lsys: inferred {len(scene.elements)} elements with {result.grammar.production_count} productions, "
        f"{100 * result.explained:.0f} % placed by repetition, "
        f"max deviation {result.max_deviation:.3g} (tolerance {result.tolerance:.3g}), "
        f"{before:.0f} -> {after:.0f} bits"
    )


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
        "stages": {k: round(v, 4) for k, v in _timings(result).items()},
        "reproduction_error": result.stages.get("reproduction_error"),
        "tolerance": result.tolerance,
        "max_deviation": result.max_deviation,
        "explained": round(result.explained, 4),
        "description_bits": {
            "before": round(result.description_bits[0], 1),
            "after": round(result.description_bits[1], 1),
        },
        "warnings": list(scene.warnings),
        "log": list(result.log),
    }


# ---------------------------------------------------------------------------
# Subcommands


@contextlib.contextmanager
def frozen_after():
    """Run a block (imports, reading the input) with the cyclic collector paused, then freeze what it made.

    The inference's modules (numpy, scipy and this package) are some 10^5 objects that live
    as long as the process.  Importing them triggered about 115 collections that freed
    nothing, and the inference's one full collection traversed them all again: together
    45–100 ms of a 0.9 s ``lsys infer`` of 1,200 elements (in-process ``gc.callbacks``).
    The scene read from the input lives as long as the command too: the first collection after
    reading a 50,052-leaf grid traversed its objects for 38-44 ms, and two later ones for 60
    ms more (the reader frees what it no longer needs itself: :func:`~lsys_core.svg.parse.parse_svg`).
    Frozen (``gc.freeze``) they are left out of later collections; :func:`lsys_core.cli.main`
    unfreezes them when the command ends, so a program that calls it keeps its collector as
    it was.  Objects are still freed by reference counting; the collector pauses only during
    the block.
    """
    enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        if enabled:
            gc.enable()


def _cmd_infer(args, progress: Progress, say: Say, symmetrize: bool = False) -> int:
    with frozen_after():
        from lsys_core.grammar import format_grammar
        from lsys_core.pipeline import infer
        from lsys_core.pipeline import symmetrize as sym_fn

    png = getattr(args, "png", None)
    outputs = [args.output, args.rules] if symmetrize else [args.output, args.svg, png, args.report]
    _check(outputs, [args.input])
    settings = _settings(args)
    _png_options(args)  # a bad PNG option fails before the inference, not after
    t0 = time.perf_counter()
    with frozen_after():  # the scene lives as long as the command, like the modules
        scene, head = _read_svg(args.input)
    t_import = time.perf_counter() - t0
    if not args.quiet:
        for w in scene.warnings:
            say(f"lsys: warning: {w}")
    if not scene.elements:
        return _infer_nothing(args, scene, head, outputs, symmetrize)
    fn = sym_fn if symmetrize else infer
    result = fn(scene, settings, progress=progress)
    t = time.perf_counter()
    drawing = _derive(result.grammar)
    result.stages["svg_import"] = t_import
    result.stages["derivation"] = time.perf_counter() - t
    progress.close()
    text = format_grammar(result.grammar)

    def report() -> dict:
        rep = _infer_report(result, scene, drawing)
        rep["seconds"] = round(time.perf_counter() - t0, 4)
        return rep

    _commit(_infer_files(args, text, drawing, report, outputs, symmetrize, head))
    if not args.quiet:
        say(_summary(result, scene))
    if args.verbose:
        for k, v in _timings(result).items():
            say(f"lsys: {k:<18} {v * 1000:9.1f} ms")
        if "reproduction_error" in result.stages:
            say(
                f"lsys: {'reproduction error':<18} {result.stages['reproduction_error']:9.2e} of the diagonal"
            )
        for line in result.log:
            say(f"lsys: {line}")
    return 0


def _cmd_derive(args, say: Say) -> int:
    from lsys_core.derive.derivation import DEFAULT_LIMIT
    from lsys_core.grammar import set_params

    _check([args.output, args.png], [args.rules])
    limit = DEFAULT_LIMIT if args.limit is None else args.limit
    if not 1 <= limit <= MAX_LIMIT:
        raise LsysError(f"--limit must be between 1 and {MAX_LIMIT:,}, got {limit:,}")
    if args.seed < 0:
        raise LsysError(f"--seed must be a whole number >= 0, got {args.seed}")
    png_options = _png_options(args)
    g = _load_rules(args.rules)
    sets = _parse_sets(args.set)
    if sets:
        g = set_params(g, sets)
    rnd = _parse_randomize(args.randomize, args.seed)
    t = time.perf_counter()
    drawing = _derive(g, limit=limit, randomize=rnd)
    seconds = time.perf_counter() - t
    _commit(_drawing_outputs(drawing, args.output, args.png, png_options, flat=args.flat))
    if args.verbose:
        say(f"lsys: derived {len(drawing):,} elements in {seconds * 1000:.1f} ms")
    return 0


def _cmd_params(args) -> int:
    from lsys_core.grammar import list_params

    g = _load_rules(args.rules)
    lines = [f"{p.key:<16} {p.value:>14.6g}  {p.kind:<15} {p.label}\n" for p in list_params(g)]
    _commit([(STDIO, "".join(lines))])
    return 0


def run_command(args: argparse.Namespace, progress: Progress, say: Say) -> int:
    """Run the subcommand ``args.command``; ``say`` prints a line on stderr."""
    if args.command == "infer":
        return _cmd_infer(args, progress, say)
    if args.command == "symmetrize":
        return _cmd_infer(args, progress, say, symmetrize=True)
    if args.command == "derive":
        return _cmd_derive(args, say)
    return _cmd_params(args)
