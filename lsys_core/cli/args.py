"""The ``lsys`` command's arguments: subcommands, options anywhere, ``-`` for standard input/output."""

from __future__ import annotations

import argparse

from lsys_core import __version__

__all__ = ["STDIO", "build_parser"]

#: The file name that means standard input (for an input) or standard output (for an output).
STDIO = "-"


def _common() -> argparse.ArgumentParser:
    """Options every subcommand accepts too, so that they may come before or after it."""
    p = argparse.ArgumentParser(add_help=False)
    g = p.add_argument_group("output on the terminal")
    # SUPPRESS: an option given before the subcommand is not reset by the subcommand's default.
    g.add_argument(
        "-q", "--quiet", action="store_true", default=argparse.SUPPRESS, help="no progress or warnings"
    )
    g.add_argument(
        "-v",
        "--verbose",
        action="store_true",
        default=argparse.SUPPRESS,
        help="print stage timings and the inference log",
    )
    return p


def _weights(p: argparse.ArgumentParser) -> None:
    from lsys_core.settings import SETTINGS

    g = p.add_argument_group("inference settings")
    for s in SETTINGS:
        g.add_argument(
            f"--{s.name}", type=float, help=f"{s.help}, in {s.range_text()} (default {s.default:g})"
        )
    g.add_argument(
        "--jobs", metavar="N", help="worker threads (default: $LSYS_JOBS, else the cores available)"
    )
    g.add_argument(
        "--deviation",
        type=float,
        metavar="LENGTH",
        help="how far the derived drawing may deviate from the input, in document units: near-identical "
        "shapes within it share a terminal, rules place elements within it (default 0.5 %% of the "
        "drawing's diagonal; 0: exact copies only)",
    )


def _flat(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--flat",
        action="store_true",
        help="write SVG as one baked <path> per instance (default: shapes once in <defs>, "
        "instances as <use>, a <g> per rule call), for tools that do not understand <use>",
    )


def _png(p: argparse.ArgumentParser) -> None:
    g = p.add_argument_group("PNG output")
    g.add_argument("--png", metavar="OUT.png", help="write the drawing as PNG ('-': standard output)")
    g.add_argument(
        "--dpi",
        type=float,
        default=96.0,
        help="dots per inch for the document's width/height in cm, in, pt, ... (default 96: 1 px per px)",
    )
    g.add_argument("--width", type=int, metavar="PX", help="image width in pixels (height follows)")
    g.add_argument("--height", type=int, metavar="PX", help="image height in pixels (width follows)")
    g.add_argument(
        "--background", metavar="COLOR", default="none", help="CSS colour behind the drawing (default none)"
    )


def build_parser() -> argparse.ArgumentParser:
    """Return the parser of the ``lsys`` command."""
    common = _common()
    p = argparse.ArgumentParser(
        prog="lsys",
        description="Turn vector art into an editable parametric L-system, and back. "
        "A file name '-' is standard input or standard output.",
    )
    p.add_argument("--version", action="version", version=f"lsys {__version__}")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress or warnings on stderr")
    p.add_argument("-v", "--verbose", action="store_true", help="print stage timings and the rule log")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")

    inf = sub.add_parser("infer", parents=[common], help="infer rules from an SVG")
    inf.add_argument("input", help="input SVG ('-': standard input)")
    inf.add_argument("-o", "--output", help="write the rules (.lsys); default: print them")
    inf.add_argument("--svg", help="write the derivation of the inferred rules as SVG")
    inf.add_argument(
        "--report", help="write a JSON report (elements, symbols, rules, axiom, seconds, stages)"
    )
    _flat(inf)
    _png(inf)
    _weights(inf)

    sym = sub.add_parser(
        "symmetrize", parents=[common], help="regularise a jittered pattern through relaxed inference"
    )
    sym.add_argument("input", help="input SVG ('-': standard input)")
    sym.add_argument("-o", "--output", required=True, help="output SVG ('-': standard output)")
    sym.add_argument("--rules", help="also write the rules (.lsys)")
    _flat(sym)
    _weights(sym)

    der = sub.add_parser("derive", parents=[common], help="derive rules into SVG/PNG")
    der.add_argument("rules", help="rules file (.lsys; '-': standard input)")
    der.add_argument("-o", "--output", required=True, help="output SVG ('-': standard output)")
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
    _flat(der)
    _png(der)

    par = sub.add_parser("params", parents=[common], help="list the numeric parameters of a rules file")
    par.add_argument("rules", help="rules file (.lsys; '-': standard input)")
    return p
