#!/usr/bin/env bash
# Install the bundle built by `make package` for one user (or under PREFIX), with its desktop
# entry, AppStream metadata and icons, so the editor shows up in the application menu.
#
#   bash packaging/install.sh                 # into ~/.local
#   PREFIX=/opt/lsys bash packaging/install.sh
#   bash packaging/install.sh --uninstall
set -euo pipefail
cd "$(dirname "$0")/.."
APP_ID="io.github.lsys_editor.LsysEditor"
PREFIX="${PREFIX:-$HOME/.local}"
BUNDLE="dist/lsys-editor"
LIB="$PREFIX/lib/lsys-editor"
SHARE="$PREFIX/share"

if [[ "${1:-}" == "--uninstall" ]]; then
    rm -rf "$LIB"
    rm -f "$PREFIX/bin/lsys" "$PREFIX/bin/lsys-editor" \
        "$SHARE/applications/$APP_ID.desktop" "$SHARE/metainfo/$APP_ID.metainfo.xml"
    find "$SHARE/icons/hicolor" -name "$APP_ID.*" -delete 2>/dev/null || true
    echo "removed lsys-editor from $PREFIX"
    exit 0
fi

[[ -x "$BUNDLE/lsys-editor" ]] || { echo "install.sh: run 'make package' first" >&2; exit 1; }
rm -rf "$LIB"
mkdir -p "$LIB" "$PREFIX/bin" "$SHARE/applications" "$SHARE/metainfo" "$SHARE/icons"
cp -a "$BUNDLE/." "$LIB/"
ln -sf "$LIB/lsys-editor" "$PREFIX/bin/lsys-editor"
ln -sf "$LIB/lsys" "$PREFIX/bin/lsys"
# Exec= names the installed binary by its full path, so the menu entry works without PATH.
sed "s|^Exec=lsys-editor|Exec=$PREFIX/bin/lsys-editor|; s|^TryExec=lsys-editor|TryExec=$PREFIX/bin/lsys-editor|" \
    "resources/$APP_ID.desktop" > "$SHARE/applications/$APP_ID.desktop"
cp "resources/$APP_ID.metainfo.xml" "$SHARE/metainfo/"
cp -r resources/icons/hicolor "$SHARE/icons/"
command -v update-desktop-database >/dev/null && update-desktop-database -q "$SHARE/applications" || true
command -v gtk-update-icon-cache >/dev/null && gtk-update-icon-cache -q -t "$SHARE/icons/hicolor" || true
echo "installed lsys-editor into $PREFIX (binaries in $PREFIX/bin)"
