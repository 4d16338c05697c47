#!/bin/sh
# The editor screenshots in the README, taken by the editor itself (lsys-editor --screenshot).
#
#   sh docs/images/screenshots.sh            # offscreen (no display needed)
#   XVFB=1 sh docs/images/screenshots.sh     # in a real X window under Xvfb (Debian: xvfb), 1280x800
#
# Writes docs/images/editor-rules.png (rule cards and structure panel), editor-handles.png
# (an instance selected, its repetition's step handle dragged) and editor-2x.png (the same
# window at device pixel ratio 2).
set -eu
cd "$(dirname "$0")/../.."
PY=${PYTHON:-.venv/bin/python}
OUT=docs/images
EX=resources/examples
if [ "${XVFB:-0}" = 1 ]; then
    run() { xvfb-run -a -s "-screen 0 2600x1700x24" env QT_QPA_PLATFORM=xcb "$PY" -m app "$@"; }
else
    run() { QT_QPA_PLATFORM=offscreen "$PY" -m app "$@"; }
fi
run "$EX/facade.svg" --screenshot "$OUT/editor-rules.png" --size 1280x800 --show cards,structure
run "$EX/flower-ring.svg" --screenshot "$OUT/editor-handles.png" --size 1280x800 \
    --show cards,structure --color-by rule --select 4 --drag 30,20
run "$EX/facade.svg" --screenshot "$OUT/editor-2x.png" --size 1280x800 --scale 2 --show cards,structure
echo "wrote $OUT/editor-rules.png $OUT/editor-handles.png $OUT/editor-2x.png"
