#!/usr/bin/env bash
# Regenerate the example gallery from the hand-written grammars in sources/:
#   NAME.svg  = `lsys derive sources/NAME.lsys` (jittered-tiles with a seeded --randomize),
#   NAME.lsys = `lsys infer NAME.svg`, the rules the program finds in that art.
# Usage: resources/examples/build.sh            (uses .venv/bin/lsys, else `lsys` on PATH)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
if [[ -n "${LSYS:-}" ]]; then
    lsys=("$LSYS")
elif [[ -x "$root/.venv/bin/lsys" ]]; then
    lsys=("$root/.venv/bin/lsys")
else
    lsys=(lsys)
fi

# The jittered example: every rule application is perturbed by up to 2 degrees and 2 %.
JITTER="angle=2,distance=0.02"
JITTER_SEED=5

cd "$here"
for src in sources/*.lsys; do
    name="$(basename "$src" .lsys)"
    if [[ "$name" == jittered-* ]]; then
        "${lsys[@]}" derive "$src" -o "$name.svg" --randomize "$JITTER" --seed "$JITTER_SEED"
    else
        "${lsys[@]}" derive "$src" -o "$name.svg"
    fi
    "${lsys[@]}" -q infer "$name.svg" -o "$name.lsys"
    echo "$name: $(grep -c '<path' "$name.svg") elements, $(grep -c -- '->' "$name.lsys") productions"
done
