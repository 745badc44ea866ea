#!/usr/bin/env bash
# This file is part of augocc. License: Apache-2.0.
# Issue 16's progress figure: the longest gap between two progress lines of `augocc run` when
# stderr is not a terminal (a log), which the issue wants at most 5 s. Synthesizes a shot
# (default 1280x720, 300 frames, 6 key frames; `augocc synth`), runs `augocc run --force` on it
# with stderr through a pipe, stamps each line as it arrives and prints every stage's line count
# and the longest gap (with the line that ended it). Minutes on the 2-core machine: not in the
# test suite (Augocc_RunDriver.progress_lines_in_a_log checks the lines, not their timing).
#
#   perf/progress_interval.sh [BIN] [OUTDIR] [WxH] [FRAMES]
set -euo pipefail
BIN=${1:-build/bin/augocc}
OUT=${2:-/tmp/augocc_progress}
SIZE=${3:-1280x720}
FRAMES=${4:-300}
mkdir -p "$OUT"
if [ ! -f "$OUT/synth/video.mp4" ] || [ ! -f "$OUT/synth.done.$SIZE.$FRAMES" ]; then
  rm -rf "$OUT/synth" "$OUT"/synth.done.*
  "$BIN" --quiet synth --out "$OUT/synth" --size "$SIZE" --frames "$FRAMES" --key-frames 6 \
    --bitrate 8
  touch "$OUT/synth.done.$SIZE.$FRAMES"
fi
cat > "$OUT/scene.yml" <<'YML'
%YAML:1.0
---
objects:
  - { name: dome, shape: dome, behind: building, distance: 0.05, size: 0.6, offset: [-0.45, 0, 0] }
YML
# Stamp each stderr line on arrival (stdout, the stage summary, goes to its own file).
{ "$BIN" run --force --input "$OUT/synth/video.mp4" --masks "$OUT/synth/input/masks" \
    --scene "$OUT/scene.yml" --out-dir "$OUT/run" 2>&1 1> "$OUT/stdout.txt" |
  while IFS= read -r line; do printf '%s %s\n' "$(date +%s.%N)" "$line"; done; } > "$OUT/log.txt"
start=$(head -n1 "$OUT/log.txt" | cut -d' ' -f1)
echo "== $SIZE x $FRAMES frames: $(wc -l < "$OUT/log.txt") progress lines"
awk '{ split($2, a, ":"); n[a[1]]++ } END { for (s in n) printf "   %-10s %d lines\n", s, n[s] }' \
  "$OUT/log.txt"
awk -v t0="$start" 'NR > 1 { g = $1 - prev; if (g > max) { max = g; at = $0 } }
  { prev = $1 } END { printf "   longest gap between lines: %.2f s (before: %s)\n", max, at }' \
  "$OUT/log.txt"
cat "$OUT/stdout.txt"
