"""Start the editor: ``lsys-editor [FILE.svg|FILE.lsys] [--screenshot OUT.png]``.

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

__all__ = ["build_parser", "main"]

SCREENSHOT_TIMEOUT_S = 180


def build_parser() -> argparse.ArgumentParser:
    """Return the command-line parser."""
    from lsys_core import __version__

    p = argparse.ArgumentParser(prog="lsys-editor", description="Edit vector art as a parametric L-system.")
    p.add_argument("--version", action="version", version=f"lsys-editor {__version__}")
    p.add_argument("file", nargs="?", help="an SVG to analyse, or an .lsys rules file")
    p.add_argument("--screenshot", metavar="OUT.png", help="save a PNG of the window once ready, then exit")
    p.add_argument("--size", default="1400x900", help="window size for --screenshot (default 1400x900)")
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


def _screenshot(app, window, out: str, timeout: float) -> int:
    """Wait until the window is idle, save a PNG of it, return the exit status."""
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

    def poll() -> None:
        idle_polls["n"] = idle_polls["n"] + 1 if window.is_idle() else 0
        if idle_polls["n"] >= 3:
            shoot()

    timer = QTimer(window)
    timer.setInterval(50)
    timer.timeout.connect(poll)
    timer.start()
    QTimer.singleShot(int(timeout * 1000), lambda: finish(1, f"not ready after {timeout:g} s"))
    app.exec()
    timer.stop()
    return status["code"]


def main(argv: Sequence[str] | None = None) -> int:
    """Run the editor; return the process exit status."""
    import multiprocessing

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
    app = QApplication.instance() or QApplication([sys.argv[0]])
    _set_identity(app)

    from .main_window import MainWindow

    if args.file and not os.path.isfile(args.file):
        print(f"lsys-editor: no such file: {args.file}", file=sys.stderr)
        if args.screenshot:
            return 1
    screenshot = bool(args.screenshot)
    window = MainWindow(QSettings(), restore_layout=not screenshot, autosave=not screenshot)
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
            code = _screenshot(app, window, args.screenshot, args.timeout)
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
