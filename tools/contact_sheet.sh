#!/usr/bin/env bash
# Synthesizes a fresh data set and writes a contact sheet of 8 of its frames with the ground-truth
# whole silhouettes outlined (building red, L-block green, tower blue), for a look by eye.
# Usage: tools/contact_sheet.sh [OUT.png] [--model perspective] [other `augocc synth` flags]
# Needs the built CLI (build/bin/augocc, or $AUGOCC_BIN).
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
bin="${AUGOCC_BIN:-$here/build/bin/augocc}"
out="${1:-$here/build/synth_contact_sheet.png}"
shift || true
if [[ ! -x "$bin" ]]; then
    echo "contact_sheet.sh: $bin not found; build first (cmake --build build --target augocc)" >&2
    exit 2
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$bin" synth --out "$work/synth" --contact-sheet "$out" "$@"
echo "contact sheet: $out"
