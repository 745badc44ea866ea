#!/usr/bin/env bash
# This file is part of augocc. License: Apache-2.0.
# Issue 15's figures on hand-held footage: `augocc demo --model handheld` (1280x720, 90 frames,
# k1 = -0.12, 1.5 scene sizes away, 6 key frames, exposure and white-balance drift, H.264 at
# 8 Mbit/s, the pipeline from its own tracker on the decoded video), run three ways:
#   calibration  the synthesized calibration.yml given to the run (augocc run --calibration)
#   self         nothing known: self-calibration of focal, k1, k2
#   ignored      no lens model (augocc before issue 15)
# Each prints the demo's accuracy lines (composite within 8 grey levels, rotation error, slide
# median / p95 / worst, focal error, key-frame and non-key matte IoU). About 10 minutes a run on
# the project's 2-core machine, so not in the test suite (see the README's Performance section).
#
#   perf/handheld_figures.sh [BIN] [OUTDIR] [MODES...]
set -euo pipefail
BIN=${1:-build/bin/augocc}
OUT=${2:-/tmp/augocc_handheld}
shift $(( $# > 2 ? 2 : $# )) || true
MODES=${*:-calibration self ignored}
mkdir -p "$OUT"
for mode in $MODES; do
  echo "== lens: $mode"
  /usr/bin/time -f "   wall %e s, peak RSS %M kB" \
    "$BIN" demo --model handheld --lens "$mode" --out-dir "$OUT/$mode" 2>&1 |
    grep -E "accuracy|slide|lens:|wall|s$" || true
done
