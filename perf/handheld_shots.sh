#!/usr/bin/env bash
# This file is part of augocc. License: Apache-2.0.
# Issue 15's camera figures on hand-held shots that are not the demo's: each shot synthesized
# with `augocc synth` (street-level hand-held path 1.5 scene sizes away, 90 frames, exposure and
# white-balance drift, H.264 at 6 Mbit/s), tracked by augocc's own tracker on the decoded video,
# cameras recovered by `augocc sfm` self-calibrated (no --calibration) and, with CAL=1, with the
# synthesized calibration.yml; then build/bin/augocc_lens_figures prints mean rotation error,
# focal error, distortion error at the image corners (test_sfm_lens.cpp's measure), slide
# (measureSlide) and, for the tracks, how far they reach towards the corners, the residual by
# radius, and how much the residual drifts along a track.
#   shot2  960x540, seed 2, k1 -0.11, k2 0.01  (the "second shot" of the README)
#   shot3  960x540, seed 5, k1 -0.14, k2 0.03
#   shot4  800x600, seed 3, k1 -0.08, k2 -0.01
# About 2-3 minutes of sfm a shot on the project's 2-core machine.
#
#   perf/handheld_shots.sh [BUILD] [OUTDIR] [SHOTS...]
set -euo pipefail
BUILD=${1:-build}
OUT=${2:-/tmp/augocc_handheld_shots}
shift $(( $# > 2 ? 2 : $# )) || true
SHOTS=${*:-shot2 shot3 shot4}
BIN=$BUILD/bin/augocc
FIG=$BUILD/bin/augocc_lens_figures
mkdir -p "$OUT"
for shot in $SHOTS; do
  case $shot in
    shot2) args="--seed 2 --size 960x540 --distortion -0.11,0.01,0,0" ;;
    shot3) args="--seed 5 --size 960x540 --distortion -0.14,0.03,0,0" ;;
    shot4) args="--seed 3 --size 800x600 --distortion -0.08,-0.01,0,0" ;;
    *) echo "unknown shot $shot" >&2; exit 2 ;;
  esac
  d=$OUT/$shot
  echo "== $shot: $args"
  # shellcheck disable=SC2086
  "$BIN" --quiet synth --out "$d" --model perspective --path handheld --frames 90 \
    --distance-ratio 1.5 --orbit 30 --exposure-drift 0.15 --white-balance-drift 0.05 \
    --bitrate 6 --key-frames 6 $args
  "$BIN" --quiet track --input "$d/video.mp4" --out "$d/tracks_own.yml"
  /usr/bin/time -f "   sfm wall %e s" "$BIN" sfm --tracks "$d/tracks_own.yml" \
    --out "$d/rec_self.yml" 2>&1 | grep -E "lens:|final BA|wall" || true
  "$FIG" "$d/rec_self.yml" "$d/gt/reconstruction.yml" "$d/tracks_own.yml"
  if [ "${CAL:-0}" = 1 ]; then
    "$BIN" sfm --tracks "$d/tracks_own.yml" --calibration "$d/calibration.yml" \
      --out "$d/rec_cal.yml" 2>&1 | grep -E "lens:|final BA" || true
    [ -f "$d/rec_cal.yml" ] && "$FIG" "$d/rec_cal.yml" "$d/gt/reconstruction.yml" | head -1
  fi
done
