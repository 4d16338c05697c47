"""Start the editor: ``lsys-editor [FILE.svg|FILE.lsys] [--screenshot OUT.png [steps]]``.

``--help`` and ``--version`` answer before Qt is loaded (they work without a display or Qt).

With ``--screenshot`` the editor opens the file, waits until inference, derivation and
rendering have finished, saves a PNG of the whole window and exits (0 on success, 1 with a
message on stderr otherwise).  It works offscreen (``QT_QPA_PLATFORM=offscreen``).
"""

from __future__ import annotations

import argparse
import logging
import os
import sys
import traceback
from collections.abc import Sequence
from typing import Any

__all__ = ["build_parser", "main", "settle_heap"]

SCREENSHOT_TIMEOUT_S = 180
#: The heap is frozen again this long after the first drawing (see :func:`settle_heap`).
FREEZE_AFTER_MS = 1000


def build_parser() -> argparse.ArgumentParser:
    """Return the command-line parser."""
    from lsys_core import __version__

    p = argparse.ArgumentParser(prog="lsys-editor", description="Edit vector art as a parametric L-system.")
    p.add_argument("--version", action="version", version=f"lsys-editor {__version__}")
    p.add_argument("file", nargs="?", help="an SVG to analyse, or an .lsys rules file")
    p.add_argument("--screenshot", metavar="OUT.png", help="save a PNG of the window once ready, then exit")
    p.add_argument("--size", default="1400x900", help="window size for --screenshot (default 1400x900)")
    shot = p.add_argument_group("screenshot steps (run in this order before the picture is taken)")
    shot.add_argument(
        "--show",
        default="",
        metavar="PANELS",
        help="raise these docks: rules, cards, params, inference, structure",
    )
    shot.add_argument(
        "--color-by", default="", choices=("", "rule", "group"), help="colour the canvas by rule or group"
    )
    shot.add_argument(
        "--select", type=int, metavar="N", help="click instance N (its repetition shows handles)"
    )
    shot.add_argument(
        "--drag", default="", metavar="DX,DY", help="drag the next-repetition handle by DX,DY pixels"
    )
    shot.add_argument("--scale", type=float, metavar="F", help="device pixel ratio (QT_SCALE_FACTOR), e.g. 2")
    p.add_argument(
        "--timeout",
        type=float,
        default=SCREENSHOT_TIMEOUT_S,
        help="seconds to wait for --screenshot (default %(default)s)",
    )
    return p


def _window_size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise SystemExit(f"lsys-editor: --size must be WIDTHxHEIGHT, got {text!r}") from None
    return max(w, 200), max(h, 200)


def _install_excepthook(window) -> None:
    """Show unexpected exceptions in the window instead of losing them (the app keeps running)."""

    def hook(exc_type, exc, tb) -> None:
        logging.getLogger("app").error("".join(traceback.format_exception(exc_type, exc, tb)))
        window.show_message(f"internal error ({exc_type.__name__}: {exc}); see the log")

    sys.excepthook = hook


def _offer_recovery(window) -> None:
    from PySide6.QtWidgets import QMessageBox

    from .recovery import discard_orphan, find_orphans

    for path, data in find_orphans():
        state = data["state"]
        name = os.path.basename(state.get("path") or state.get("scene_path") or "") or "an untitled document"
        answer = QMessageBox.question(
            window,
            "Recover unsaved work",
            f"The editor did not exit cleanly. Restore the unsaved work on {name}?",
            QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No,
            QMessageBox.StandardButton.Yes,
        )
        if answer == QMessageBox.StandardButton.Yes:
            window.doc.restore(state)
            discard_orphan(path)
            return
        discard_orphan(path)


def settle_heap(window: Any) -> None:
    """Freeze the heap now and once more a second after the window's first drawing.

    See :func:`app.core.freeze_heap`: what exists when the window is built lives as long as
    the process, and so do the modules first imported to open, derive and draw a document.
    Only the editor's process does this (not every window: a test session opens hundreds).
    """
    from PySide6.QtCore import QTimer

    from . import core

    core.freeze_heap(collect=True)

    def first_drawing(_drawing: Any) -> None:
        window.doc.drawingChanged.disconnect(first_drawing)
        QTimer.singleShot(FREEZE_AFTER_MS, window, core.freeze_heap)

    window.doc.drawingChanged.connect(first_drawing)


def main(argv: Sequence[str] | None = None) -> int:
    """Run the editor; return the process exit status."""
    import multiprocessing

    from lsys_core.cpu import prefer_fast_sort, prefer_small_pages

    prefer_fast_sort()  # before numpy is imported; the inference process inherits them
    prefer_small_pages()
    multiprocessing.freeze_support()  # the inference worker process of a frozen build
    args = build_parser().parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    from .syscheck import problem

    missing = None if _qt_running() else problem()
    if missing:  # Qt would abort naming only the first missing library
        print(f"lsys-editor: {missing}", file=sys.stderr)
        return 1
    from PySide6.QtCore import QCoreApplication, QSettings
    from PySide6.QtWidgets import QApplication

    QCoreApplication.setOrganizationName("lsys-editor")
    QCoreApplication.setApplicationName("lsys-editor")
    if args.scale:
        os.environ["QT_SCALE_FACTOR"] = f"{args.scale:g}"  # read when the application starts
    app = QApplication.instance() or QApplication([sys.argv[0]])
    _set_identity(app)

    from .main_window import MainWindow
    from .screenshot import steps_from_args, take_screenshot

    if args.file and not os.path.isfile(args.file):
        print(f"lsys-editor: no such file: {args.file}", file=sys.stderr)
        if args.screenshot:
            return 1
    screenshot = bool(args.screenshot)
    window = MainWindow(QSettings(), restore_layout=not screenshot, autosave=not screenshot)
    settle_heap(window)
    _install_excepthook(window)
    if screenshot:
        window.resize(*_window_size(args.size))
    window.show()
    if not screenshot:
        _offer_recovery(window)
    if args.file and os.path.isfile(args.file):
        window.open_path(args.file)
    try:
        if screenshot:
            steps = steps_from_args(window, args.show, args.color_by, args.select, args.drag)
            code = take_screenshot(app, window, args.screenshot, args.timeout, steps)
            window.doc.undo_stack.setClean()  # a screenshot run never asks to save
            window.close()
            return code
        return app.exec()
    finally:
        window.shutdown()


def _qt_running() -> bool:
    """Whether a QApplication already runs in this process (tests): its plugin has loaded."""
    if "PySide6.QtWidgets" not in sys.modules:
        return False
    from PySide6.QtWidgets import QApplication

    return QApplication.instance() is not None


def _set_identity(app) -> None:
    """Give the windows the application icon and link them to the desktop entry."""
    from PySide6.QtGui import QGuiApplication, QIcon

    from .resources import APP_ID, icon_path

    QGuiApplication.setDesktopFileName(APP_ID)
    icon = icon_path()
    if icon is not None:
        app.setWindowIcon(QIcon(str(icon)))


if __name__ == "__main__":
    sys.exit(main())
