#!/bin/bash
# The farm's speed-up on this machine (doc/farm.md, README "Performance"): a single-node Slurm
# cluster (test/farm/slurm_cluster.sh, as root), one synthesized shot tracked, solved and cloned
# once, then its composite stage (the chunk array and the join) submitted with 1, 2 and 4 chunks.
# Prints the wall time of each from submission to the join's end and the ratios T1/T2, T1/T4.
# Usage: perf/farm_speedup.sh [AUGOCC_BINARY] [FRAMES] [WIDTHxHEIGHT] (default build/bin/augocc,
# 48 frames, 640x360). ONE_CORE=1 makes every job single-threaded (OpenCV's parallel_for_ and
# llvmpipe, through --setup): one core per chunk, as a farm gives each task its own node or core.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
AUGOCC=$(realpath "${1:-$root/build/bin/augocc}")
FRAMES=${2:-48}
SIZE=${3:-640x360}
# shellcheck source=SCRIPTDIR/../test/farm/slurm_cluster.sh
. "$root/test/farm/slurm_cluster.sh"
[ "$(id -u)" -eq 0 ] || { echo "farm_speedup: run as root (it starts a Slurm cluster)" >&2; exit 2; }
cluster_have_slurm || { echo "farm_speedup: slurm-wlm and munge are not installed" >&2; exit 2; }

T=$(mktemp -d /tmp/augocc_farm_perf.XXXXXX)
trap 'cluster_stop; rm -rf "$T"' EXIT
"$AUGOCC" --quiet synth --out "$T/src" --frames "$FRAMES" --size "$SIZE"
printf '%s\n' '%YAML:1.0' '---' 'objects:' \
    '  - { name: tree, shape: tree, in_front_of: building, distance: 0.15, size: 0.6 }' \
    '  - { name: dome, shape: dome, behind: building, distance: 0.05, size: 0.6 }' >"$T/scene.yml"
cluster_start "$T/cluster"
sb=$(command -v sbatch)
setup=()
if [ "${ONE_CORE:-0}" = 1 ]; then
    setup=(--setup 'export OPENCV_FOR_THREADS_NUM=1 LP_NUM_THREADS=1')
fi
farm() {
    "$AUGOCC" --quiet farm --input "$T/src/video.mp4" --masks "$T/src/input/masks" \
        --scene "$T/scene.yml" --augocc "$AUGOCC" --sbatch "$sb" "${setup[@]}" "$@"
}
# Tracking, camera recovery and the clones once (one job each, not part of the figure).
farm --out-dir "$T/base" --chunks 1
cluster_wait 3600
declare -A secs chunk_secs
for n in 1 2 4; do
    d=$T/chunks$n
    mkdir -p "$d"
    cp "$T/base/tracks.yml" "$T/base/reconstruction.yml" "$T/base/clones.yml.gz" "$d/"
    start=$(date +%s.%N)
    farm --out-dir "$d" --chunks "$n"
    # The chunk array ends when every chunk's composite is there (written all or nothing).
    while [ "$(find "$d/chunks" -mindepth 2 -maxdepth 2 -name composite 2>/dev/null | wc -l)" \
        -lt "$n" ]; do
        sleep 0.05
    done
    mid=$(date +%s.%N)
    cluster_wait 3600
    end=$(date +%s.%N)
    [ -f "$d/composite.mp4" ] || { echo "farm_speedup: $n chunks: no composite.mp4" >&2; exit 1; }
    secs[$n]=$(python3 -c "print(f'{$end - $start:.2f}')")
    chunk_secs[$n]=$(python3 -c "print(f'{$mid - $start:.2f}')")
    echo "chunks $n: ${secs[$n]} s, of which the chunk array ${chunk_secs[$n]} s ($FRAMES frames $SIZE)"
done
python3 - "${secs[1]}" "${secs[2]}" "${secs[4]}" "${chunk_secs[1]}" "${chunk_secs[2]}" \
    "${chunk_secs[4]}" "$(nproc)" <<'PY'
import sys
t1, t2, t4, c1, c2, c4 = map(float, sys.argv[1:7])
print(f"speed-up on {sys.argv[7]} cores, submission to the join's end: 2 chunks {t1 / t2:.2f}x, "
      f"4 chunks {t1 / t4:.2f}x (T1/T2, T1/T4)")
print(f"speed-up of the chunk array alone: 2 chunks {c1 / c2:.2f}x, 4 chunks {c1 / c4:.2f}x")
PY
