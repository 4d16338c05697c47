#!/usr/bin/env bash
# Build the installable app: dist/lsys-editor/, one PyInstaller folder with both executables
# (`lsys-editor` and `lsys`), the examples and the icons, then smoke-test it.
#
#   bash packaging/build.sh          (what `make package` runs; several minutes the first time)
#
# The build uses its own virtualenv under build/ (never the repository's .venv), into which it
# installs the project as a wheel and PyInstaller from PyPI. Environment:
#   PYTHON       interpreter for the build venv (default: python3)
#   PYINSTALLER  requirement spec for PyInstaller (default: "pyinstaller>=6.3")
#   SKIP_SMOKE=1 build only
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT="$(pwd)"
PYTHON="${PYTHON:-python3}"
PYINSTALLER="${PYINSTALLER:-pyinstaller>=6.3}"
VENV="$ROOT/build/package-venv"
WORK="$ROOT/build/pyinstaller"
DIST="$ROOT/dist"
BUNDLE="$DIST/lsys-editor"

step() { printf '\n== %s\n' "$*"; }

step "build venv ($VENV)"
if [[ ! -x "$VENV/bin/python" ]]; then
    "$PYTHON" -m venv "$VENV"
fi
"$VENV/bin/python" -m pip install --quiet --upgrade pip
# Stale setuptools output would leak deleted modules into the wheel.
rm -rf "$ROOT/build/lib" "$ROOT/build/bdist."*
"$VENV/bin/python" -m pip install --quiet "$ROOT" "$PYINSTALLER"
"$VENV/bin/python" -m pip install --quiet --force-reinstall --no-deps "$ROOT"
rm -rf "$ROOT/build/lib" "$ROOT/build/bdist."*
"$VENV/bin/python" -m PyInstaller --version

step "pyinstaller"
rm -rf "$BUNDLE"
# Run from build/ so the checkout's sources cannot shadow the installed package.
(cd "$ROOT/build" && "$VENV/bin/python" -m PyInstaller --noconfirm --clean --log-level WARN \
    --distpath "$DIST" --workpath "$WORK" "$ROOT/packaging/lsys-editor.spec")
for exe in lsys lsys-editor; do
    [[ -x "$BUNDLE/$exe" ]] || { echo "build.sh: $BUNDLE/$exe is missing" >&2; exit 1; }
done
echo "bundle: $BUNDLE ($(du -sh "$BUNDLE" | cut -f1))"

if [[ "${SKIP_SMOKE:-0}" == 1 ]]; then
    exit 0
fi

step "smoke test"
SMOKE="$ROOT/build/smoke"
rm -rf "$SMOKE" "$ROOT/build/smoke.png"
mkdir -p "$SMOKE"
EXAMPLES="$(find "$BUNDLE" -type d -path '*/resources/examples' | head -n 1)"
[[ -f "$EXAMPLES/helix.svg" ]] || { echo "build.sh: examples are not in the bundle" >&2; exit 1; }
# A clean environment and a neutral working directory: only the bundle can be used.
run() { (cd "$SMOKE" && env -u PYTHONPATH -u PYTHONHOME -u VIRTUAL_ENV "$@"); }
run "$BUNDLE/lsys" --version
run "$BUNDLE/lsys" -q infer "$EXAMPLES/helix.svg" -o "$SMOKE/helix.lsys" --png "$SMOKE/helix.png"
run "$BUNDLE/lsys" derive "$SMOKE/helix.lsys" -o "$SMOKE/helix.svg" --set m=60
grep -q '<use' "$SMOKE/helix.svg"
QT_QPA_PLATFORM=offscreen run "$BUNDLE/lsys-editor" "$ROOT/resources/examples/helix.svg" \
    --screenshot "$ROOT/build/smoke.png"
head -c 8 "$ROOT/build/smoke.png" | od -An -tx1 | tr -d ' \n' | grep -q '^89504e470d0a1a0a$' \
    || { echo "build.sh: build/smoke.png is not a PNG" >&2; exit 1; }
echo "smoke test passed: lsys infer/derive and lsys-editor --screenshot (build/smoke.png)"
