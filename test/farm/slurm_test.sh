#!/bin/bash
# augocc farm on a real single-node Slurm cluster (issue 21; doc/farm.md): a tiny synthesized
# shot in 4 composite chunks; the joined outputs must equal a single-machine `augocc composite`
# and `augocc matte` of the same inputs (PNG folders byte for byte, the H.264 video frame for
# frame after decoding, 16 frames each by ffprobe). Then chunk 2 is killed mid-way, `augocc farm
# resume` submits it alone (and the join), and the result is the same again.
# Usage: slurm_test.sh AUGOCC_BINARY. Exit 77 (CTest: skipped) without slurm-wlm/munge or root.
set -euo pipefail
AUGOCC=$(realpath "$1")
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=SCRIPTDIR/slurm_cluster.sh
. "$here/slurm_cluster.sh"

if [ "$(id -u)" -ne 0 ]; then
    echo "SKIP: the Slurm test starts munged, slurmctld and slurmd as root; not root"
    exit 77
fi
if ! cluster_have_slurm; then
    echo "SKIP: slurm-wlm and munge are not installed (scripts/setup.sh installs them)"
    exit 77
fi

T=$(mktemp -d /tmp/augocc_farm_test.XXXXXX)
cleanup() {
    cluster_stop
    rm -rf "$T"
}
trap cleanup EXIT
fail() {
    echo "FAIL: $*" >&2
    for f in "$T"/shot/farm/logs/*; do
        [ -f "$f" ] && { echo "--- $f" >&2; cat "$f" >&2; }
    done
    exit 1
}

# The shot: 16 frames of 160x120, its key-frame masks, a tree in front of the building.
"$AUGOCC" --quiet synth --out "$T/src" --frames 16 --size 160x120
cat >"$T/scene.yml" <<'YML'
%YAML:1.0
---
objects:
  - { name: tree, shape: tree, in_front_of: building, distance: 0.15, size: 0.6 }
  - { name: dome, shape: dome, behind: building, distance: 0.05, size: 0.6, offset: [-0.45, 0, 0] }
YML
video=$T/src/video.mp4
masks=$T/src/input/masks

cluster_start "$T/cluster" || fail "the cluster did not start"
"$AUGOCC" farm --input "$video" --masks "$masks" --scene "$T/scene.yml" --out-dir "$T/shot" \
    --chunks 4 --augocc "$AUGOCC" --sbatch "$(command -v sbatch)" --time 00:10:00 |
    tee "$T/submit.txt"
grep -q "chunks 0-3" "$T/submit.txt" || fail "the 4 chunks were not submitted as one array"
nobj=$(find "$masks" -mindepth 1 -maxdepth 1 -type d | wc -l)
grep -q "2-clone job [0-9]* (objects 0-$((nobj - 1)))" "$T/submit.txt" ||
    fail "the $nobj objects' clones were not submitted as one array"
cluster_wait 600 || fail "the jobs did not finish"
[ -f "$T/shot/composite.mp4" ] || fail "no joined composite.mp4"
# The merged per-object parts are the single-machine clones file, byte for byte.
"$AUGOCC" --quiet clone --reconstruction "$T/shot/reconstruction.yml" --masks "$masks" \
    --tracks "$T/shot/tracks.yml" --input "$video" --out "$T/ref_clones.yml.gz"
cmp -s "$T/ref_clones.yml.gz" "$T/shot/clones.yml.gz" ||
    fail "the farm's merged clones differ from a single-machine augocc clone"

# Single machine, the same inputs (the shot's own reconstruction and clones).
"$AUGOCC" --quiet composite --input "$video" --reconstruction "$T/shot/reconstruction.yml" \
    --clones "$T/shot/clones.yml.gz" --scene "$T/scene.yml" --out "$T/ref_composite" \
    --mattes "$T/ref_mattes"
"$AUGOCC" --quiet composite --input "$video" --reconstruction "$T/shot/reconstruction.yml" \
    --clones "$T/shot/clones.yml.gz" --scene "$T/scene.yml" --out "$T/ref.mp4"

frames_of() {
    ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames \
        -of csv=p=0 "$1"
}
check_same() {
    local what=$1
    diff -r "$T/ref_composite" "$T/shot/composite" >/dev/null ||
        fail "$what: the joined composite PNGs differ from the single-machine run"
    diff -r "$T/ref_mattes" "$T/shot/mattes" >/dev/null ||
        fail "$what: the joined mattes differ from the single-machine run"
    [ "$(find "$T/shot/composite" -name '*.png' | wc -l)" -eq 16 ] ||
        fail "$what: the joined composite does not hold 16 frames"
    [ "$(frames_of "$T/shot/composite.mp4")" = 16 ] ||
        fail "$what: composite.mp4 does not hold 16 frames"
    [ "$(ffprobe -v error -select_streams v:0 -show_entries stream=codec_name -of csv=p=0 \
        "$T/shot/composite.mp4")" = "$(ffprobe -v error -select_streams v:0 \
        -show_entries stream=codec_name -of csv=p=0 "$T/ref.mp4")" ] ||
        fail "$what: the joined video's codec differs from the single-machine one"
    # The decoded frames, in order, as faithful to the lossless frames as the single-machine
    # video. Not hash-equal: OpenCV 4.6's H.264 writer (x264, frame threads) does not give the
    # same bytes twice for the same frames when the process is busy (measured: 3 runs of one
    # `composite --out x.mp4`, 2 distinct videos, PSNR 42-46 dB between them). So: per frame,
    # PSNR of each video against the joined PNG frame k; the joined video's within 1 dB of the
    # single-machine one's (two encodes differ by <= 0.1 dB here; x264's own error is ~40 dB),
    # and >= 30 dB (a wrong or shifted frame scores ~20 dB against frame k).
    psnr_of() {
        ffmpeg -v error -framerate 25 -pattern_type glob -i "$T/shot/composite/*.png" -i "$1" \
            -lavfi "[0:v]format=yuv420p[a];[a][1:v]psnr=stats_file=$2" -f null - ||
            fail "$what: cannot compare $1 with the PNG frames"
    }
    psnr_of "$T/ref.mp4" "$T/ref.psnr"
    psnr_of "$T/shot/composite.mp4" "$T/joined.psnr"
    local bad
    bad=$(paste -d' ' "$T/ref.psnr" "$T/joined.psnr" | awk '{
        for (i = 1; i <= NF; i++) if ($i ~ /^psnr_avg:/) { split($i, a, ":"); v[++n] = a[2] }
        r = v[n - 1]; j = v[n]; n = 0
        if (r == "inf") r = 99; if (j == "inf") j = 99
        if (j < 30 || j < r - 1) printf "frame %d: joined %.2f dB, single machine %.2f dB; ", NR - 1, j, r
    }')
    [ "$(wc -l <"$T/joined.psnr")" = 16 ] || fail "$what: the video comparison saw $(wc -l <"$T/joined.psnr") frames"
    [ -z "$bad" ] || fail "$what: the joined video's frames are less faithful than the single-machine video's: $bad"
    echo "$what: joined outputs = single-machine outputs (16 frames)"
}
check_same "4 chunks"

# Chunk 2 killed mid-way: its outputs (and the join's) gone as if it had not finished yet,
# then its script run by hand and killed (SIGKILL) while its temporary output exists.
chunk=$T/shot/chunks/0008-0012
rm -rf "$chunk" "$T/shot/composite" "$T/shot/mattes" "$T/shot/composite.mp4"
# Its own session, so that the kill reaches augocc and not only the shell running it.
SLURM_ARRAY_TASK_ID=2 setsid bash "$T/shot/farm/4-chunks.sh" >"$T/killed.log" 2>&1 &
pid=$!
killed=0
for _ in $(seq 3000); do
    if compgen -G "$chunk/.composite.tmp*" >/dev/null; then
        kill -KILL -- "-$pid"
        killed=1
        break
    fi
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.01
done
wait "$pid" 2>/dev/null || true
[ "$killed" = 1 ] || fail "chunk 2 ended before it could be killed mid-way"
[ ! -e "$chunk/composite" ] || fail "a chunk killed mid-way left a composite (not all or nothing)"
compgen -G "$chunk/.composite.tmp*" >/dev/null || fail "the killed chunk left no temporary"

"$AUGOCC" farm resume --out-dir "$T/shot" --sbatch "$(command -v sbatch)" | tee "$T/resume.txt"
grep -q "4-chunks job [0-9]* (chunks 2)" "$T/resume.txt" ||
    fail "resume did not submit chunk 2 alone"
if grep -q "1-sfm\|2-clone\|3-merge" "$T/resume.txt"; then
    fail "resume submitted a finished stage again"
fi
cluster_wait 600 || fail "the resumed jobs did not finish"
if compgen -G "$chunk/.composite.tmp*" >/dev/null; then
    fail "the killed chunk's temporary is still there after the resume"
fi
check_same "chunk 2 killed and resumed"
"$AUGOCC" farm resume --out-dir "$T/shot" --sbatch "$(command -v sbatch)" | grep -q "nothing to submit" ||
    fail "resume of a finished shot submitted something"

started=("${CLUSTER_PIDS[@]}")
cluster_stop
for pid in "${started[@]}"; do
    kill -0 "$pid" 2>/dev/null && fail "daemon $pid still running"
done
echo "PASS"
