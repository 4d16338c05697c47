"""How many workers the inference uses, and an order-keeping parallel map on threads.

The parallel parts of the inference are independent numpy-heavy tasks (sampling chunks of
elements, matching chunks of candidates against a representative, the two kinds of cluster
analysis of a level, the step clusters of every (d, s) cluster).  numpy releases the GIL in
its array loops, so threads share the work without copying the scene into other processes;
results never depend on the number of workers (every task computes the same thing, and the
results are put back in order).

The number of workers follows the cores this process may run on (``os.process_cpu_count()``
or the CPU affinity), and can be set with the ``LSYS_JOBS`` environment variable or
:func:`set_jobs` (the command's ``--jobs``).

Work nests (the linear sequences run beside the constant clusters and split into parts, whose
counts split again), and each :func:`pmap` starts threads of its own; at most :func:`jobs` of
them compute at once: a worker takes one of ``jobs() - 1`` tokens before it starts (the calling
thread holds the last), and a thread that waits for its workers lends them its token.  With a
thread per task, the first level of a 50,052-leaf grid ran up to four analyses at once on two
cores, each with its arrays: with the tokens, whole ``lsys infer`` with 2 jobs took 0.93x the
time (5.85 -> 5.58 s) and 0.93x the CPU, peak 998 -> 946 MiB (5 alternating pairs); 20,008
leaves 0.94x; the wind chart of the real-art set (mean shift in parts) the same (1.01x, 3 pairs).

On glibc every thread that allocates gets a heap of its own (an *arena*), and memory freed in
one is not reused by another: with two workers, a 60,000-leaf grid needed more than the 2 GiB
of address space a process may be given (1.6 GiB of it resident), with one arena it infers
within it (42 s either way at load 2.5).  Importing this module therefore asks the C library
for one arena (``mallopt(M_ARENA_MAX, 1)``; elsewhere nothing happens).  The workers allocate
few, large arrays, so they hardly ever wait for each other's allocations.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
import threading
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Generic, TypeVar

from lsys_core.errors import LsysError

__all__ = [
    "MAX_JOBS",
    "SWITCH_INTERVAL",
    "Pending",
    "available_cores",
    "jobs",
    "keep_freed_memory",
    "pmap",
    "runs",
    "set_jobs",
    "submit",
    "switching_often",
]

#: Largest accepted number of workers.
MAX_JOBS = 256
#: The environment variable that sets the number of workers.
ENV = "LSYS_JOBS"

T = TypeVar("T")
R = TypeVar("R")

_override: int | None = None
_M_ARENA_MAX = -8  # glibc's mallopt parameters
_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3
#: Freed memory a process that runs inferences keeps for its next arrays (see :func:`keep_freed_memory`).
KEEP_FREED = 1 << 30


def _glibc() -> ctypes.CDLL | None:
    """The C library of this process if it is glibc, else None (musl has no arenas to tune)."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        libc = ctypes.CDLL(None)
    except OSError:
        return None
    return libc if hasattr(libc, "gnu_get_libc_version") else None


_GLIBC = _glibc()


def _mallopt(param: int, value: int) -> bool:
    """glibc's ``mallopt(param, value)``; False where it refuses or the C library is not glibc."""
    return _GLIBC is not None and bool(_GLIBC.mallopt(param, value))


#: Whether glibc was asked for a single malloc arena (see the module docstring).
ONE_ARENA = _mallopt(_M_ARENA_MAX, 1)


def keep_freed_memory() -> bool:
    """Let this process reuse the memory of freed large arrays instead of returning it at once.

    glibc gives every allocation above a threshold (at most 32 MiB) pages of its own and
    returns them when it is freed; the inference allocates and frees arrays of 10^7 entries
    many times, and the kernel clears every new page again.  That took 18.6 of the 57.7 s of
    CPU time of a 100,010-leaf grid (6.3 of 26 s at 50,052).  With large allocations in the
    heap and up to :data:`KEEP_FREED` of freed memory kept: 10.5 and 3.6 s, for 6 % (100k) and
    3 % (50k) more peak memory.  Called by the ``lsys`` command, whose process ends with its
    inference; not on import (a program that uses the library, such as the editor, whose
    inference process lives on between runs, decides for its own process).
    Returns False where the C library is not glibc.
    """
    return _mallopt(_M_MMAP_THRESHOLD, KEEP_FREED) and _mallopt(_M_TRIM_THRESHOLD, KEEP_FREED)


#: How long a thread may hold the interpreter while another one waits for it (seconds; Python's
#: default is 5 ms), while this process infers: see :func:`switching_often`.
SWITCH_INTERVAL = 0.001


@contextlib.contextmanager
def switching_often() -> Iterator[None]:
    """Within this block, a thread waiting for the interpreter gets it after :data:`SWITCH_INTERVAL`.

    A worker between two numpy calls waits for the interpreter lock while the main thread runs
    Python; with Python's 5 ms interval it often waits the whole of it for a call that takes
    less, then its core idles.  With 1 ms the two-job inference of a 50,052-leaf grid took 0.977×
    the time (8.35 against 8.62 s, 4 alternating pairs) and 0.97× the CPU; one job runs no
    thread and is unaffected.  The interval is the process's: used by the ``lsys`` command and
    the editor's inference process, which run nothing else; the previous interval is restored
    after the block.
    """
    previous = sys.getswitchinterval()
    sys.setswitchinterval(min(previous, SWITCH_INTERVAL))
    try:
        yield
    finally:
        sys.setswitchinterval(previous)


def available_cores() -> int:
    """The cores this process may run on (affinity where the system tells it)."""
    count = getattr(os, "process_cpu_count", None)
    if count is not None:
        return max(1, count() or 1)
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def _parse(text: str, origin: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise LsysError(f"{origin} must be a whole number of workers, got {text!r}") from None
    if not 1 <= n <= MAX_JOBS:
        raise LsysError(f"{origin} must be between 1 and {MAX_JOBS}, got {n}")
    return n


def set_jobs(n: int | str | None) -> None:
    """Use ``n`` workers from now on (None: back to ``LSYS_JOBS`` or the available cores)."""
    global _override
    _override = None if n is None else _parse(str(n), "--jobs")


def jobs() -> int:
    """The number of workers: :func:`set_jobs`, else ``LSYS_JOBS``, else the available cores."""
    if _override is not None:
        return _override
    text = os.environ.get(ENV, "").strip()
    return _parse(text, ENV) if text else available_cores()


_gates: dict[int, threading.Semaphore] = {}
_gates_lock = threading.Lock()


def _gate(n: int) -> threading.Semaphore:
    """The cores of ``n`` workers as tokens: ``n - 1`` to take, one held by the calling thread."""
    with _gates_lock:
        gate = _gates.get(n)
        if gate is None:
            gate = _gates[n] = threading.Semaphore(n - 1)
        return gate


def _gated(gate: threading.Semaphore, fn: Callable[..., R], *args, **kwargs) -> R:
    """``fn(*args, **kwargs)`` once this worker thread holds a token."""
    gate.acquire()
    try:
        return fn(*args, **kwargs)
    finally:
        gate.release()


@contextlib.contextmanager
def _waiting(gate: threading.Semaphore) -> Iterator[None]:
    """While a thread waits for its workers, its token is theirs."""
    gate.release()
    try:
        yield
    finally:
        gate.acquire()


def pmap(fn: Callable[[T], R], items: Iterable[T], *, workers: int | None = None) -> list[R]:
    """``[fn(x) for x in items]``, on up to ``workers`` (default :func:`jobs`) threads.

    Nested calls (a worker's own ``pmap``) share the :func:`jobs` cores: at most that many
    threads compute at once, a thread that waits for its workers lending them its core.
    """
    todo = list(items)
    n = min(workers if workers is not None else jobs(), len(todo))
    if n <= 1:
        return [fn(x) for x in todo]
    gate = _gate(jobs())
    with _waiting(gate), ThreadPoolExecutor(max_workers=n, thread_name_prefix="lsys") as pool:
        return [f.result() for f in [pool.submit(_gated, gate, fn, x) for x in todo]]


class Pending(Generic[R]):
    """The value of work :func:`submit` started; :meth:`result` waits for it (or raises its error)."""

    def __init__(self, future: Future[R], gate: threading.Semaphore | None) -> None:
        self._future, self._gate = future, gate

    def result(self) -> R:
        """The value (waiting for it, the core of this thread lent to the workers)."""
        if self._gate is None or self._future.done():
            return self._future.result()
        with _waiting(self._gate):
            return self._future.result()


def submit(fn: Callable[..., R], *args, **kwargs) -> Pending[R]:
    """Run ``fn(*args, **kwargs)`` beside the caller on a thread when there are ≥ 2 workers.

    With one worker it runs at once; either way ``.result()`` gives its value (or raises).
    """
    fut: Future[R]
    if jobs() <= 1:
        fut = Future()
        try:
            fut.set_result(fn(*args, **kwargs))
        except BaseException as e:
            fut.set_exception(e)
        return Pending(fut, None)
    gate = _gate(jobs())
    pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="lsys")
    fut = pool.submit(_gated, gate, fn, *args, **kwargs)
    pool.shutdown(wait=False)
    return Pending(fut, gate)


def runs(sizes: Iterable[int], cap: int) -> list[tuple[int, int]]:
    """Split items of these sizes into runs, in order, each of ≤ ``cap`` (a larger item is a run of its own).

    For independent items (clusters, texts) worked in runs whose results are concatenated in
    order: memory stays bounded whatever the input's size, and small inputs stay in one run.
    Returns ``(lo, hi)`` item ranges.
    """
    out, lo, acc, count = [], 0, 0, 0
    for i, size in enumerate(sizes):
        if acc and acc + size > cap:
            out.append((lo, i))
            lo, acc = i, 0
        acc += size
        count = i + 1
    if count:
        out.append((lo, count))
    return out
