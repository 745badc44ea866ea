#!/bin/bash
# An exported shot.py run from Blender's Scripting tab (issue 20: not only `blender -b -P`): a
# small synthesized shot is exported, and Blender's interface (under Xvfb) opens the script in a
# Text Editor and runs it twice from there (run_in_text_editor.py checks what it built).
# Exits 77 (skipped) without Blender or xvfb-run. Usage: scripting_tab_test.sh AUGOCC_BINARY
set -euo pipefail
AUGOCC=$(realpath "$1")
HERE=$(dirname "$(realpath "$0")")
BLENDER=${AUGOCC_BLENDER:-blender}
for tool in "$BLENDER" xvfb-run; do
    if ! command -v "$tool" >/dev/null; then
        echo "SKIP: $tool is not installed (scripts/setup.sh installs blender and xvfb)"
        exit 77
    fi
done
T=$(mktemp -d /tmp/augocc_blender_ui.XXXXXX)
trap 'rm -rf "$T"' EXIT
printf '%s\n' '%YAML:1.0' '---' 'objects:' \
    '  - { name: tree, shape: tree, in_front_of: building, distance: 0.15, size: 0.6 }' \
    >"$T/scene.yml"
"$AUGOCC" --quiet synth --out "$T/src" --frames 6 --key-frames 2 --size 160x120
"$AUGOCC" --quiet clone --reconstruction "$T/src/gt/reconstruction.yml" \
    --masks "$T/src/input/masks" --out "$T/clones.yml.gz"
"$AUGOCC" --quiet export-blender --input "$T/src/frames" \
    --reconstruction "$T/src/gt/reconstruction.yml" --clones "$T/clones.yml.gz" \
    --scene "$T/scene.yml" --out "$T/shot/shot.py"
status=0
timeout 240 xvfb-run -a "$BLENDER" --factory-startup -P "$HERE/run_in_text_editor.py" -- \
    "$T/shot/shot.py" >"$T/blender.log" 2>&1 || status=1
grep -E '^scripting_tab|Error|Traceback' "$T/blender.log" || { cat "$T/blender.log"; status=1; }
exit $status
