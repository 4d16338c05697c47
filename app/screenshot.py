"""``lsys-editor FILE --screenshot OUT.png``: a picture of the window once everything is drawn.

The window opens the file, waits until inference, derivation and rendering are done, then runs
the requested steps as a user would (raise panels, colour by rule, click an instance, drag a
handle), waiting again after each, and saves a PNG of the whole window at the screen's device
pixel ratio (``--scale 2`` gives a 2× picture).  It works offscreen
(``QT_QPA_PLATFORM=offscreen``) and under Xvfb (``docs/images/screenshots.sh``).
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

__all__ = ["steps_from_args", "take_screenshot"]

DOCKS = {
    "rules": "rules_dock",
    "cards": "cards_dock",
    "params": "params_dock",
    "inference": "inference_dock",
    "structure": "structure_dock",
}


def steps_from_args(
    window: Any, show: str = "", color_by: str = "", select: int | None = None, drag: str = ""
) -> list:
    """Return the steps a screenshot runs before it is taken (see the module docstring)."""
    steps: list[Callable[[], None]] = []
    for name in filter(None, (part.strip() for part in show.split(","))):
        if name not in DOCKS:
            raise SystemExit(f"lsys-editor: --show takes {', '.join(DOCKS)}, got {name!r}")
        steps.append(getattr(window, DOCKS[name]).raise_)
    if color_by:
        steps.append(lambda: window.set_color_mode(color_by))
    if select is not None:
        steps.append(lambda: window.canvas.elementClicked.emit(select))
    if drag:
        try:
            dx, dy = (float(v) for v in drag.split(","))
        except ValueError:
            raise SystemExit(f"lsys-editor: --drag must be DX,DY in pixels, got {drag!r}") from None
        steps.append(lambda: drag_handle(window, dx, dy))
    return steps


def drag_handle(window: Any, dx: float, dy: float, which: str = "move") -> bool:
    """Drag handle ``which`` of the selection by ``(dx, dy)`` logical pixels, with mouse events."""
    from PySide6.QtCore import QEvent, QPointF, Qt
    from PySide6.QtGui import QMouseEvent
    from PySide6.QtWidgets import QApplication

    h = window.handles.handles
    if h is None or which not in h.points():
        print(
            f"lsys-editor: note: no {which} handle to drag (select an instance of a repetition)",
            file=sys.stderr,
        )
        return False
    canvas = window.canvas
    z = h.points()[which]
    start = QPointF(*canvas.view.to_widget(z.real, z.imag))
    left, none = Qt.MouseButton.LeftButton, Qt.MouseButton.NoButton

    def send(kind, pos: QPointF, button, buttons) -> None:
        event = QMouseEvent(
            kind, pos, canvas.mapToGlobal(pos), button, buttons, Qt.KeyboardModifier.NoModifier
        )
        QApplication.sendEvent(canvas, event)

    send(QEvent.Type.MouseButtonPress, start, left, left)
    for k in range(1, 7):
        send(QEvent.Type.MouseMove, start + QPointF(dx * k / 6, dy * k / 6), none, left)
    send(QEvent.Type.MouseButtonRelease, start + QPointF(dx, dy), left, none)
    return True


def take_screenshot(app, window, out: str, timeout: float, steps: list[Callable[[], None]] = ()) -> int:
    """Wait until the window is idle, run each step (waiting until idle after each), save a PNG.

    Returns the exit status (0: saved).
    """
    from PySide6.QtCore import QBuffer, QByteArray, QIODevice, QTimer

    from lsys_core.errors import LsysError

    from . import core

    status = {"code": 1, "done": False}
    errors: list[str] = []
    window.doc.message.connect(errors.append)
    window.canvas.message.connect(errors.append)

    def finish(code: int, message: str = "") -> None:
        if status["done"]:
            return
        status["done"] = True
        status["code"] = code
        if message:
            print(f"lsys-editor: {message}", file=sys.stderr)
        window.doc.undo_stack.setClean()  # steps edit the rules; a screenshot run never asks to save
        app.quit()

    def shoot() -> None:
        if status["done"]:
            return
        if window.doc.drawing is None:
            finish(1, errors[-1] if errors else "nothing was derived")
            return
        pixmap = window.grab()
        data = QByteArray()
        buf = QBuffer(data)
        buf.open(QIODevice.OpenModeFlag.WriteOnly)
        if not pixmap.save(buf, "PNG"):
            finish(1, "could not encode the screenshot")
            return
        try:
            core.write_atomic(out, bytes(data.data()))
        except LsysError as exc:
            finish(1, str(exc))
            return
        for e in errors:
            print(f"lsys-editor: note: {e}", file=sys.stderr)
        finish(0)

    idle_polls = {"n": 0}

    todo = list(steps)

    def poll() -> None:
        idle_polls["n"] = idle_polls["n"] + 1 if window.is_idle() else 0
        if idle_polls["n"] >= 3:
            if todo:
                idle_polls["n"] = 0
                todo.pop(0)()
            else:
                shoot()

    timer = QTimer(window)
    timer.setInterval(50)
    timer.timeout.connect(poll)
    timer.start()
    QTimer.singleShot(int(timeout * 1000), lambda: finish(1, f"not ready after {timeout:g} s"))
    app.exec()
    timer.stop()
    return status["code"]
