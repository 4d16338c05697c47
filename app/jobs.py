"""The computations the editor runs off the UI thread, as plain picklable functions.

Each job takes an immutable request (a snapshot made on the UI thread), a cancel token and a
progress callback, and calls into ``lsys_core``.  The module imports no Qt, so the inference
worker process (:class:`~app.workers.ProcessCompute`) loads no Qt GUI module.

The worker keeps the analysis of the last scene it inferred (similarity, instancing,
transformation spaces, clustering: :func:`lsys_core.pipeline.analyse`), keyed by a digest of the
scene.  A new weight or tolerance then re-runs only importance, rule generation,
post-processing and derivation; a new similarity threshold or deviation redoes the analysis.
Measured on the 1,200-element scene of ``tests/bench/bench_editor.py``: whole inference
1.08 s analysis + 1.55 s rules; a weight change with the kept analysis 0.2–0.3 s.
"""

from __future__ import annotations

import hashlib
import pickle
from dataclasses import dataclass, replace
from typing import Any

from lsys_core.cancel import CancelToken, Progress
from lsys_core.derive.derivation import derive
from lsys_core.errors import Cancelled, LsysError
from lsys_core.grammar.model import Randomize

from . import core

__all__ = [
    "DERIVE_LIMIT",
    "DeriveRequest",
    "InferOutcome",
    "InferRequest",
    "infer_kept",
    "run_derive",
    "run_inference",
    "scene_digest",
]

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
    analyse_only: bool = False  # only analyse ``scene`` and keep the analysis here (rules not returned)
    scene_key: bytes | None = None  # scene_digest(scene) when the requester knows it


@dataclass(frozen=True)
class InferOutcome:
    """Result of an inference job: the inference result, the grammar, its text and drawing.

    ``scene`` is the loaded scene when the request asked to load a file (else None: the
    requester has it already, and it need not travel back from a worker process).  ``grammar``
    is the inferred grammar with the request's randomization.  ``scene_key`` is the digest the
    worker keeps the scene's analysis under (the requester sends it back with later requests:
    the worker then finds its analysis without the requester digesting the scene);
    ``reused_analysis`` says whether this run found the scene's analysis kept.
    """

    scene: Any
    result: Any
    text: str
    drawing: Any
    derive_error: str | None = None
    grammar: Any = None
    scene_key: bytes | None = None
    reused_analysis: bool = False


@dataclass(frozen=True)
class DeriveRequest:
    """What a derivation job needs: the grammar and how to perturb it (None: as the grammar says)."""

    grammar: Any
    randomize: Randomize | None = None
    limit: int = DERIVE_LIMIT


_KEPT: list[tuple[bytes, Any]] = []  # (scene digest, Analysis) of the last scene inferred here


def scene_digest(scene: Any) -> bytes:
    """A digest of everything in ``scene`` (its pickled form): equal scenes, equal digests.

    Pickled with protocol 4, which writes an array's bytes whatever its flags: protocol 5
    writes a read-only array (as the SVG reader makes them) as ``bytes`` and a writeable one as
    ``bytearray``, so a scene sent through a pipe (whose arrays come back writeable) had another
    digest than the worker's own, and the first weight change after opening a file analysed
    the scene again (1.2 s of the 1.4 s it took at 1,200 elements).
    """
    return hashlib.blake2b(pickle.dumps(scene, protocol=4), digest_size=20).digest()


def infer_kept(
    scene: Any, settings: Any, cancel: CancelToken, progress: Progress, key: bytes | None = None
) -> tuple[Any, bytes, bool]:
    """Infer ``scene`` with ``settings``, reusing the analysis kept from the same scene.

    Only what the settings change is computed again (:func:`lsys_core.pipeline.analyse` with
    ``previous``); the result is what :func:`lsys_core.pipeline.infer` gives.  ``key`` is the
    scene's digest if the requester knows it (digesting 1,200 elements takes 11 ms).
    Returns the result, the key the analysis is kept under and whether the kept one was reused.
    """
    key = key or scene_digest(scene)
    previous = _KEPT[0][1] if _KEPT and _KEPT[0][0] == key else None
    if previous is not None:
        scene = previous.scene  # the very object the kept analysis holds
    else:
        _KEPT.clear()  # a new scene: let the old analysis go before the new one is made
    analysis = core.analyse(scene, settings, previous=previous, cancel=cancel, progress=progress)
    _KEPT[:] = [(key, analysis)]
    return core.rules_from_analysis(analysis, cancel=cancel, progress=progress), key, previous is not None


def run_inference(request: InferRequest, cancel: CancelToken, progress: Progress) -> InferOutcome:
    """Load (if asked), infer or symmetrize, format and derive; runs on a worker."""
    scene = request.scene if request.scene is not None else core.load_svg(request.svg_path)
    if request.load_only:  # its key digested here, not on the requester's UI thread
        return InferOutcome(scene, None, "", None, scene_key=scene_digest(scene))
    key, reused = request.scene_key, False
    if request.symmetrize:
        result = core.symmetrize(scene, request.settings, cancel=cancel, progress=progress)
    else:
        result, key, reused = infer_kept(scene, request.settings, cancel, progress, key)
        if request.analyse_only:  # a restored session: the first weight change finds the analysis
            # and its level cache, which generating the rules once filled (they are dropped)
            return InferOutcome(None, None, "", None, scene_key=key, reused_analysis=reused)
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
    loaded = scene if request.scene is None else None
    return InferOutcome(loaded, result, text, drawing, error, grammar, key, reused)


def run_derive(request: DeriveRequest, cancel: CancelToken, progress: Progress) -> Any:
    """Derive the grammar into a drawing; runs on a worker."""
    return derive(request.grammar, limit=request.limit, randomize=request.randomize, cancel=cancel)
