"""Benchmark the editor's responsiveness (run it, it is not a test).

    QT_QPA_PLATFORM=offscreen python tests/bench/bench_editor.py [--json OUT.json] [--quick]

Reports, in milliseconds:

* parameter slider → repainted canvas, for 10,000 and 100,000 elements: while dragging
  (draft frames; target ≤ 16 ms for 10,000 and ≤ 250 ms for 100,000) and after the release
  (full anti-aliased quality; target ≤ 100 ms for 10,000).  Each move is timed from
  ``QSlider.setValue`` on the UI thread to the end of a synchronous ``repaint()`` that shows
  the frame of the new value.  The drag bends every row into overlapping coils, so the
  released frame is drawn instance by instance (``lsys_core.render.raster`` batches full-quality
  frames only where instances do not overlap: see ``bench_render.py``'s "rows" scene).
* the longest UI-thread stall while inference of a 1,200-element scene runs in the background,
  with inference in a worker thread and in a worker process: a 2 ms QTimer on the UI thread
  records the gaps between its ticks (a stall is a gap minus the 2 ms period).
* handle drag at 10,000 elements: a pointer move on the next-repetition handle → the draft
  frame of the new step on screen (target ≤ 16 ms), timed like the slider moves.
* weight change → new rules shown, for 300 and 1,200 elements (target ≤ 300 ms at 1,200): from
  typing a new weight into the inference panel to the new rules in the text, the panels and a
  full-quality frame on the canvas (inference in the editor's worker process).  The first
  change after opening the file is printed apart (it once analysed the scene again).
* the longest UI stall while new rules with 600 parameters are applied (target ≤ 50 ms), as the
  gap of a 1 ms timer, with the UI thread's own CPU time in that gap (the rest is waiting for a
  core: on a loaded machine the wall time overstates the stall).

Scenes are derived from grammars and exported with ``lsys_core`` into a temporary folder.
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from lsys_core.cpu import prefer_fast_sort, prefer_small_pages

prefer_fast_sort()  # as the editor does first thing, before numpy is imported
prefer_small_pages()

LEAF = '"M 0 0 Q 5 -8 14 -2 Q 9 2 0 0 Z" style "fill:#66bb6a;stroke:#1b5e20;stroke-width:0.6"'


def grid_grammar(
    rows: int, cols: int, step: float = 16.0, bend: float = 0.2, gap: float | None = None
) -> str:
    """Return .lsys text of ``rows`` × ``cols`` leaves, each row curved by ``bend`` degrees a step."""
    gap = step if gap is None else gap
    return (
        f"lsys 1\nterminal A {LEAF}\naxiom: Q({rows - 1})\n"
        f"P(m): m > 0 -> A f({step}) +({bend}) P(m-1)\nP(m): m == 0 -> A\n"
        f"Q(m): m > 0 -> [ P({cols - 1}) ] +(90) f({gap}) -(90) Q(m-1)\nQ(m): m == 0 -> P({cols - 1})\n"
    )


def wait_until(app, cond, timeout: float = 60.0, signals=()) -> None:
    """Run the event loop until ``cond()`` holds: checked when one of ``signals`` fires, and
    every 5 ms in case none does."""
    from PySide6.QtCore import QEventLoop, Qt, QTimer

    if cond():
        return
    loop = QEventLoop()
    timer = QTimer()
    timer.setInterval(5)
    deadline = time.perf_counter() + timeout

    def check(*_args) -> None:
        if cond() or time.perf_counter() > deadline:
            loop.quit()

    timer.timeout.connect(check)
    for signal in signals:
        signal.connect(check, type=Qt.ConnectionType.QueuedConnection)
    timer.start()
    loop.exec()
    timer.stop()
    for signal in signals:
        signal.disconnect(check)
    if not cond():
        raise TimeoutError("condition not reached")


def make_window(**kwargs):
    from PySide6.QtCore import QSettings

    from app.main_window import MainWindow

    settings = QSettings(os.path.join(tempfile.gettempdir(), "lsys-bench.ini"), QSettings.Format.IniFormat)
    win = MainWindow(settings, restore_layout=False, autosave=False, **kwargs)
    win.resize(1400, 900)
    win.show()
    from app.__main__ import settle_heap

    settle_heap(win)  # as the editor's main() does
    return win


def frame_ready(win) -> bool:
    """Whether the canvas holds a frame of the document's current drawing, nothing pending."""
    doc, canvas = win.doc, win.canvas
    return (
        not doc.busy
        and not canvas.runner.busy
        and canvas._frame is not None
        and canvas._frame.drawing is doc.drawing
    )


def open_grid(app, workdir: Path, rows: int, cols: int):
    """Return a window showing the ``rows`` × ``cols`` grid grammar (no inference process)."""
    from app.jobs import run_inference

    path = workdir / f"grid-{rows}x{cols}.lsys"
    path.write_text(grid_grammar(rows, cols), encoding="utf-8")
    # No inference here: without a worker process, no process start-up (imports) competes with
    # the timed frames for the two cores.
    win = make_window(infer_compute=run_inference)
    win.open_path(str(path))
    wait_until(app, win.is_idle)
    return win


def bench_slider(app, workdir: Path, rows: int, cols: int, moves: int) -> dict:
    """Time slider moves while dragging (drafts) and the full-quality frame after release."""
    win = open_grid(app, workdir, rows, cols)
    n = len(win.doc.drawing)
    row = win.params_panel.rows["P.0.2.v"]  # the +(0.2) bend of every row
    drag, derive_ms, render_ms, full = [], [], [], []
    for _ in range(3):  # repeat whole gestures; the first warms caches up
        row.slider.setSliderDown(True)
        start = row.slider.value()
        for k in range(1, moves + 1):
            t0 = time.perf_counter()
            row.slider.setValue(start + 3 * k)
            wait_until(app, lambda: frame_ready(win), signals=(win.canvas.runner.resultReady,))
            win.canvas.repaint()
            drag.append((time.perf_counter() - t0) * 1e3)
            render_ms.append(win.canvas.last_frame_seconds * 1e3)
            assert win.canvas._frame.draft
        t0 = time.perf_counter()
        row.slider.setSliderDown(False)
        wait_until(app, win.is_idle)
        win.canvas.repaint()
        full.append((time.perf_counter() - t0) * 1e3)
        assert not win.canvas._frame.draft
        win.doc.undo_stack.undo()
        wait_until(app, win.is_idle)
    t0 = time.perf_counter()
    from lsys_core.derive.derivation import derive

    for _ in range(5):
        derive(win.doc.grammar)
    derive_ms.append((time.perf_counter() - t0) / 5 * 1e3)
    win.doc.undo_stack.setClean()
    win.close()
    drag = drag[moves:]  # drop the warm-up gesture
    return {
        "elements": n,
        "drag_median_ms": statistics.median(drag),
        "drag_p90_ms": sorted(drag)[int(0.9 * (len(drag) - 1))],
        "draft_render_median_ms": statistics.median(render_ms[moves:]),
        "derive_ms": derive_ms[0],
        "release_to_full_quality_ms": statistics.median(full[1:]),
    }


def bench_stall(app, workdir: Path, in_process: bool, seconds: float) -> dict:
    """Longest gap of a 2 ms UI timer while a 1,200-element scene is inferred in the background."""
    from PySide6.QtCore import QTimer

    from app.jobs import run_inference
    from lsys_core.derive.derivation import derive
    from lsys_core.grammar import parse_grammar
    from lsys_core.render.svg import export_svg

    svg = workdir / "scene1200.svg"
    if not svg.exists():
        # curved rows: a scene whose inference takes long enough to watch (tens of seconds)
        export_svg(derive(parse_grammar(grid_grammar(30, 40, step=20.0, bend=3.0, gap=25.0))), svg)
    win = make_window(**({} if in_process else {"infer_compute": run_inference}))
    if in_process:
        win.doc.warm_up()
        time.sleep(1.5)  # let the process finish its imports, as it does while the window opens
    ticks: list[float] = []
    timer = QTimer()
    timer.setInterval(2)
    timer.timeout.connect(lambda: ticks.append(time.perf_counter()))
    t_open = time.perf_counter()
    win.open_path(str(svg))
    timer.start()
    try:
        wait_until(app, lambda: not win.doc.inference.busy, timeout=seconds)
        finished = True
    except TimeoutError:
        finished = False
    elapsed = time.perf_counter() - t_open
    t_cancel = time.perf_counter()
    win.doc.cancel_inference()
    wait_until(app, lambda: not win.doc.inference.busy, timeout=30)
    cancel_s = time.perf_counter() - t_cancel
    timer.stop()
    gaps = [(b - a) * 1e3 - 2.0 for a, b in itertools.pairwise(ticks)]
    win.close()
    return {
        "mode": "process" if in_process else "thread",
        "elements": 1200,
        "observed_s": round(elapsed, 2),
        "inference_finished": finished,
        "max_stall_ms": max(gaps) if gaps else float("nan"),
        "p99_stall_ms": sorted(gaps)[int(0.99 * (len(gaps) - 1))] if gaps else float("nan"),
        "ticks": len(ticks),
        "cancel_s": round(cancel_s, 3),
    }


def bench_handle_drag(app, workdir: Path, rows: int, cols: int, moves: int) -> dict:
    """Time drags of the next-repetition handle: pointer move → draft frame on screen."""
    from PySide6.QtCore import QEvent, QPointF, Qt
    from PySide6.QtGui import QMouseEvent
    from PySide6.QtWidgets import QApplication

    win = open_grid(app, workdir, rows, cols)
    canvas = win.canvas
    win.canvas.elementClicked.emit(0)
    h = win.handles.handles
    x, y = canvas.view.to_widget(h.b1.real, h.b1.imag)
    start = QPointF(x, y)

    def send(kind, pos: QPointF, buttons) -> None:
        button = Qt.MouseButton.LeftButton if kind != QEvent.Type.MouseMove else Qt.MouseButton.NoButton
        event = QMouseEvent(
            kind, pos, canvas.mapToGlobal(pos), button, buttons, Qt.KeyboardModifier.NoModifier
        )
        QApplication.sendEvent(canvas, event)

    times = []
    for gesture in range(3):
        send(QEvent.Type.MouseButtonPress, start, Qt.MouseButton.LeftButton)
        for k in range(1, moves + 1):
            t0 = time.perf_counter()
            send(QEvent.Type.MouseMove, start + QPointF(0.0, 0.7 * k), Qt.MouseButton.LeftButton)
            wait_until(app, lambda: frame_ready(win), signals=(canvas.runner.resultReady,))
            canvas.repaint()
            if gesture:
                times.append((time.perf_counter() - t0) * 1e3)
            assert canvas._frame.draft
        send(QEvent.Type.MouseButtonRelease, start + QPointF(0.0, 0.7 * moves), Qt.MouseButton.NoButton)
        wait_until(app, win.is_idle)
        win.doc.undo_stack.undo()
        wait_until(app, win.is_idle)
    n = len(win.doc.drawing)
    steps = win.doc.undo_stack.count()
    win.doc.undo_stack.setClean()
    win.close()
    return {
        "elements": n,
        "median_ms": statistics.median(times),
        "p90_ms": sorted(times)[int(0.9 * (len(times) - 1))],
        "undo_steps_left": steps,
    }


def scene_svg(workdir: Path, rows: int, cols: int) -> Path:
    """Return an SVG of ``rows`` × ``cols`` leaves in gently curved rows (exported once)."""
    from lsys_core.derive.derivation import derive
    from lsys_core.grammar import parse_grammar
    from lsys_core.render.svg import export_svg

    svg = workdir / f"scene-{rows}x{cols}.svg"
    if not svg.exists():
        export_svg(derive(parse_grammar(grid_grammar(rows, cols, step=20.0, bend=3.0, gap=25.0))), svg)
    return svg


def bench_reweight(app, workdir: Path, rows: int, cols: int, repeats: int) -> dict:
    """Time weight changes (typed into the inference panel) until the new rules are on screen."""
    win = make_window()
    win.doc.warm_up()
    win.open_path(str(scene_svg(workdir, rows, cols)))
    wait_until(app, win.is_idle, timeout=600)
    spin = win.inference_panel.rows["wh"].spin
    times, changed = [], 0
    for k in range(repeats):
        before = win.doc.text
        t0 = time.perf_counter()
        spin.setValue(0.5 if k % 2 == 0 else 1.0)
        wait_until(app, lambda: win.doc.pending_settings is None and win.is_idle(), timeout=600)
        win.canvas.repaint()
        times.append((time.perf_counter() - t0) * 1e3)
        changed += win.doc.text != before
    n = len(win.doc.drawing)
    win.doc.undo_stack.setClean()
    win.close()
    return {
        "elements": n,
        "first_ms": times[0],
        "median_ms": statistics.median(times),
        "max_ms": max(times),
        "changed": changed,
    }


def many_params_grammar(rules: int, shift: int) -> str:
    """Return .lsys text with ``rules`` sequences of 5 numbers each (a big, flat grammar)."""
    lines = ["lsys 1", 'terminal A "M 0 0 L 4 0 L 4 4 Z" style "fill:#789"']
    lines.append("axiom: " + " ".join(f"[ f({i * 7 + shift}) +(90) P{i}(3) ]" for i in range(rules)))
    for i in range(rules):
        a = i % 7 + 1
        lines.append(f"P{i}(m): m > 0 -> A +({a}) f(10) *(0.99) +(-{a}) P{i}(m-1)")
        lines.append(f"P{i}(m): m == 0 -> A")
    return "\n".join(lines) + "\n"


class _TickRecorder(list):
    """A list filled with (wall, UI-thread CPU) times by a 1 ms timer."""

    def __init__(self) -> None:
        from PySide6.QtCore import QTimer

        super().__init__()
        self.timer = QTimer()
        self.timer.setInterval(1)
        self.timer.timeout.connect(lambda: self.append((time.perf_counter(), time.thread_time())))
        self.timer.start()


def bench_apply_stall(app, workdir: Path, repeats: int) -> dict:
    """Longest gap of a 1 ms UI timer while rules with ~600 parameters replace others."""
    from app.jobs import run_inference
    from lsys_core.grammar import list_params, parse_grammar

    path = workdir / "many.lsys"
    path.write_text(many_params_grammar(120, 0), encoding="utf-8")
    win = make_window(infer_compute=run_inference)
    win.open_path(str(path))
    wait_until(app, win.is_idle)
    worst = (0.0, 0.0)
    params = 0
    for k in range(repeats):
        grammar = parse_grammar(many_params_grammar(120 - k % 2, k + 1))  # another set of parameters
        params = len(list_params(grammar))
        ticks = _TickRecorder()
        wait_until(app, lambda t=ticks: len(t) > 10)
        win.doc.apply_grammar(grammar, "bench")
        wait_until(app, win.is_idle)
        seen = len(ticks)
        wait_until(app, lambda t=ticks, n=seen: len(t) > n + 10)
        ticks.timer.stop()
        for (w0, c0), (w1, c1) in itertools.pairwise(ticks):
            if (w1 - w0) * 1e3 > worst[0]:
                worst = ((w1 - w0) * 1e3, (c1 - c0) * 1e3)
    win.doc.undo_stack.setClean()
    win.close()
    return {"params": params, "max_stall_ms": worst[0], "ui_cpu_in_it_ms": worst[1]}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", help="also write the figures to this file")
    parser.add_argument("--quick", action="store_true", help="fewer moves and a shorter inference window")
    parser.add_argument("--stall-seconds", type=float, default=20.0, help="longest inference observed")
    parser.add_argument(
        "--only",
        default="slider,stall,reweight,apply,handles",
        help="comma-separated parts to run (default: all)",
    )
    args = parser.parse_args(argv)
    parts = set(args.only.split(","))
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance() or QApplication([])
    moves = 5 if args.quick else 12
    out: dict = {"slider": [], "stall": []}
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        targets = {10_000: (16, 100), 100_000: (250, None)}
        for rows, cols in ((100, 100), (250, 400)) if "slider" in parts else ():
            r = bench_slider(app, work, rows, cols, moves)
            out["slider"].append(r)
            drag_target, full_target = targets[r["elements"]]
            print(
                f"{r['elements']:>7,} elements: drag {r['drag_median_ms']:.1f} ms median (target ≤ {drag_target}; "
                f"p90 {r['drag_p90_ms']:.1f}; draft render {r['draft_render_median_ms']:.1f}, "
                f"derive {r['derive_ms']:.1f}), release → full quality {r['release_to_full_quality_ms']:.1f} ms"
                + (f" (target ≤ {full_target})" if full_target else ""),
                flush=True,
            )
        seconds = 8.0 if args.quick else args.stall_seconds
        for in_process in (False, True) if "stall" in parts else ():
            r = bench_stall(app, work, in_process, seconds)
            out["stall"].append(r)
            print(
                f"inference of 1,200 elements in a {r['mode']:7s}: longest UI stall {r['max_stall_ms']:.1f} ms, "
                f"p99 {r['p99_stall_ms']:.1f} ms over {r['observed_s']} s "
                f"({'finished' if r['inference_finished'] else 'still running'}; cancel took {r['cancel_s']} s)",
                flush=True,
            )
        for rows, cols in ((15, 20), (30, 40)) if "reweight" in parts else ():
            r = bench_reweight(app, work, rows, cols, 3 if args.quick else 6)
            out.setdefault("reweight", []).append(r)
            print(
                f"weight change → rules shown, {r['elements']:,} elements: first {r['first_ms']:.0f} ms, "
                f"{r['median_ms']:.0f} ms median, {r['max_ms']:.0f} ms max (target ≤ 300 ms at 1,200, "
                f"the first included; rules changed {r['changed']} times)",
                flush=True,
            )
        for r in [bench_apply_stall(app, work, 2 if args.quick else 4)] if "apply" in parts else []:
            out["apply_stall"] = r
            print(
                f"applying rules with {r['params']} parameters: longest UI stall {r['max_stall_ms']:.1f} ms "
                f"(UI-thread CPU in it {r['ui_cpu_in_it_ms']:.1f} ms; target ≤ 50)",
                flush=True,
            )
        for r in [bench_handle_drag(app, work, 100, 100, moves)] if "handles" in parts else []:
            out["handles"] = r
            print(
                f"handle drag at {r['elements']:,} elements: pointer move → draft frame {r['median_ms']:.1f} ms "
                f"median, p90 {r['p90_ms']:.1f} ms (target ≤ 16)",
                flush=True,
            )
    if args.json:
        Path(args.json).write_text(json.dumps(out, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
