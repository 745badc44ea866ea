#!/usr/bin/env bash
# This file is part of augocc. License: Apache-2.0.
# Issue 16's table: wall time and peak memory of every stage of the pipeline, per resolution and
# shot length. For each case WxH:N it synthesizes a shot (`augocc synth`: N frames of WxH, the
# scaled orthographic orbit, 6 key frames; its time and peak on stderr, not in the row) and runs
# the stages `augocc run` runs, one process each so that each has its own peak: track (the
# video), sfm, clone (tracks and photo-consistency over the video), matte, composite (the demo's
# dome and tree under its sun, to H.264). Prints one Markdown row per case: seconds / peak RSS in
# MB per stage, and the total.
#
#   perf/stage_table.sh [BIN] [OUTDIR] [WxH:N ...]
# default cases: 640x480:60 640x480:300 1280x720:60 1280x720:300 1920x1080:60 1920x1080:300
set -euo pipefail
BIN=${1:-build/bin/augocc}
OUT=${2:-/tmp/augocc_stage_table}
shift $(( $# > 2 ? 2 : $# )) || true
CASES=${*:-640x480:60 640x480:300 1280x720:60 1280x720:300 1920x1080:60 1920x1080:300}
mkdir -p "$OUT"

SCENE="$OUT/scene.yml"
cat > "$SCENE" <<'EOF'
%YAML:1.0
---
objects:
   -
      name: dome
      shape: dome
      behind: building
      distance: 0.05
      size: 0.6
      offset: [ -0.45, 0., 0. ]
   -
      name: tree
      shape: tree
      in_front_of: building
      distance: 0.15
      size: 0.6
      offset: [ -0.2, 0., 0. ]
sun:
   azimuth: 150.
   elevation: 55.
   sky: 0.5
   penumbra: 3.
EOF

# stage NAME ARGS...: runs BIN ARGS under /usr/bin/time; appends "seconds MB" to the row.
row=""
total=0
stage() {
    local name=$1
    shift
    local t="$D/time_$name.txt"
    /usr/bin/time -f "%e %M" -o "$t" "$BIN" --quiet "$name" "$@" > "$D/log_$name.txt" 2>&1 || {
        echo "stage_table: $name failed for $case (log: $D/log_$name.txt)" >&2
        tail -5 "$D/log_$name.txt" >&2
        exit 1
    }
    read -r secs kb < "$t"
    row="$row | $secs s / $(( kb / 1024 )) MB"
    total=$(echo "$total + $secs" | bc)
}

echo "| shot | track | sfm | clone | matte | composite | total |"
echo "|---|---|---|---|---|---|---|"
for case in $CASES; do
    size=${case%%:*}
    frames=${case##*:}
    D="$OUT/${size}_$frames"
    rm -rf "$D"
    mkdir -p "$D"
    /usr/bin/time -f "%e %M" -o "$D/time_synth.txt" \
        "$BIN" --quiet synth --out "$D/shot" --size "$size" --frames "$frames" > "$D/log_synth.txt" 2>&1
    read -r secs kb < "$D/time_synth.txt"
    echo "stage_table: $case synthesized in $secs s, peak $(( kb / 1024 )) MB (not in the row)" >&2
    row="| $size x $frames"
    total=0
    stage track --input "$D/shot/video.mp4" --out "$D/tracks.yml"
    stage sfm --tracks "$D/tracks.yml" --out "$D/reconstruction.yml"
    stage clone --reconstruction "$D/reconstruction.yml" --masks "$D/shot/input/masks" \
        --tracks "$D/tracks.yml" --input "$D/shot/video.mp4" --out "$D/clones.yml.gz"
    stage matte --reconstruction "$D/reconstruction.yml" --clones "$D/clones.yml.gz" \
        --out "$D/mattes"
    stage composite --input "$D/shot/video.mp4" --reconstruction "$D/reconstruction.yml" \
        --clones "$D/clones.yml.gz" --scene "$SCENE" --out "$D/composite.mp4"
    echo "$row | $total s |"
    rm -rf "$D/shot/frames" "$D/mattes"  # keep the disk use of long cases bounded
done
