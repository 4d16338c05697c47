"""The computations the editor runs off the UI thread, as plain picklable functions.

Each job takes an immutable request (a snapshot made on the UI thread), a cancel token and a
progress callback, and calls into ``lsys_core``.  The module imports no Qt, so the inference
worker process (:class:`~app.workers.ProcessCompute`) loads no Qt GUI module.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

from lsys_core.cancel import CancelToken, Progress
from lsys_core.derive.derivation import derive
from lsys_core.errors import Cancelled, LsysError
from lsys_core.grammar.model import Randomize

from . import core

__all__ = ["DERIVE_LIMIT", "DeriveRequest", "InferOutcome", "InferRequest", "run_derive", "run_inference"]

DERIVE_LIMIT = 1_000_000


@dataclass(frozen=True)
class InferRequest:
    """What an inference job needs, snapshot on the UI thread.

    ``scene`` is None when ``svg_path`` is to be loaded first (opening a file); ``randomize``
    is kept in the inferred grammar (the document's current randomization).
    """

    scene: Any
    settings: Any
    randomize: Randomize | None = None
    symmetrize: bool = False
    svg_path: str | None = None
    limit: int = DERIVE_LIMIT
    load_only: bool = False  # only load ``svg_path`` (restoring a session), no inference


@dataclass(frozen=True)
class InferOutcome:
    """Result of an inference job: the inference result, the grammar, its text and drawing.

    ``scene`` is the loaded scene when the request asked to load a file (else None: the
    requester has it already, and it need not travel back from a worker process).  ``grammar``
    is the inferred grammar with the request's randomization.
    """

    scene: Any
    result: Any
    text: str
    drawing: Any
    derive_error: str | None = None
    grammar: Any = None


@dataclass(frozen=True)
class DeriveRequest:
    """What a derivation job needs: the grammar and how to perturb it (None: as the grammar says)."""

    grammar: Any
    randomize: Randomize | None = None
    limit: int = DERIVE_LIMIT


def run_inference(request: InferRequest, cancel: CancelToken, progress: Progress) -> InferOutcome:
    """Load (if asked), infer or symmetrize, format and derive; runs on a worker."""
    scene = request.scene if request.scene is not None else core.load_svg(request.svg_path)
    if request.load_only:
        return InferOutcome(scene, None, "", None)
    run = core.symmetrize if request.symmetrize else core.infer
    result = run(scene, request.settings, cancel=cancel, progress=progress)
    grammar = replace(result.grammar, randomize=request.randomize)
    text = core.format_grammar(grammar)
    try:
        drawing = derive(grammar, limit=request.limit, cancel=cancel)
    except Cancelled:
        raise
    except LsysError as exc:  # the rules are still worth showing
        drawing, error = None, str(exc)
    else:
        error = None
    return InferOutcome(scene if request.scene is None else None, result, text, drawing, error, grammar)


def run_derive(request: DeriveRequest, cancel: CancelToken, progress: Progress) -> Any:
    """Derive the grammar into a drawing; runs on a worker."""
    return derive(request.grammar, limit=request.limit, randomize=request.randomize, cancel=cancel)
