#!/bin/bash
# `augocc farm --dry-run` on a shots file of 3 shots (issue 21): it prints every shot's five
# scripts and the sbatch calls, submits nothing, and all of it is clean for Debian's shellcheck
# package. No Slurm needed. Usage: farm_dry_run_test.sh AUGOCC_BINARY
set -euo pipefail
AUGOCC=$(realpath "$1")
if ! command -v shellcheck >/dev/null; then
    echo "SKIP: shellcheck is not installed (scripts/setup.sh installs it)"
    exit 77
fi
T=$(mktemp -d /tmp/augocc_farm_dry.XXXXXX)
trap 'rm -rf "$T"' EXIT
fail() {
    echo "FAIL: $*" >&2
    exit 1
}

"$AUGOCC" --quiet synth --out "$T/src" --frames 8 --size 96x72
printf '%s\n' '%YAML:1.0' '---' 'objects:' \
    '  - { name: tree, shape: tree, in_front_of: building, distance: 0.15, size: 0.6 }' \
    >"$T/scene.yml"
cat >"$T/shots.txt" <<'TXT'
# input          masks             scene      out-dir
src/video.mp4    src/input/masks   scene.yml  out/shot_a
src/frames       src/input/masks   scene.yml  out/shot_b
src/video.mp4    src/input/masks   -          out/shot_c   # mattes only
TXT
# An sbatch that fails: a dry run must not call it.
printf '#!/bin/sh\necho called >"%s/sbatch_called"\nexit 1\n' "$T" >"$T/sbatch"
chmod +x "$T/sbatch"
(cd "$T" && "$AUGOCC" farm --shots shots.txt --chunk-frames 3 --partition short \
    --account vfx --time 00:30:00 --setup 'module load opencv' --augocc /opt/augocc/bin/augocc \
    --sbatch "$T/sbatch" --dry-run) >"$T/printed.txt"
[ ! -e "$T/sbatch_called" ] || fail "--dry-run called sbatch"

n=0
for shot in shot_a shot_b shot_c; do
    for s in 1-sfm 2-clone 3-merge 4-chunks 5-join; do
        f=$T/out/$shot/farm/$s.sh
        [ -x "$f" ] || fail "$f was not written"
        grep -qxF "# ==> $f <==" "$T/printed.txt" || fail "$f was not printed"
        # The printed text is the file's.
        awk -v h="# ==> $f <==" '$0 == h {p = 1; next} /^# ==> / || /^# submission/ {p = 0}
            p' "$T/printed.txt" | diff - <(cat "$f"; echo) >/dev/null ||
            fail "the printed $s.sh of $shot differs from the file"
        shellcheck "$f" || fail "$f is not shellcheck-clean"
        n=$((n + 1))
    done
    grep -q "^#SBATCH --array=0-2$" "$T/out/$shot/farm/4-chunks.sh" ||
        fail "$shot: 8 frames in chunks of 3 are not an array of 3"
    # One clone task per object of the masks folder, each writing its part; the merge reads all.
    nobj=$(find "$T/src/input/masks" -mindepth 1 -maxdepth 1 -type d | wc -l)
    grep -q "^#SBATCH --array=0-$((nobj - 1))$" "$T/out/$shot/farm/2-clone.sh" ||
        fail "$shot: the clone array is not one task per object ($nobj)"
    [ "$(grep -c 'clones.parts/' "$T/out/$shot/farm/3-merge.sh")" = "$nobj" ] ||
        fail "$shot: the merge does not read one part per object"
done
[ "$(grep -c '^# submission of shot' "$T/printed.txt")" = 3 ] || fail "not 3 submissions"
# The sbatch calls as printed, one shell snippet: shellcheck-clean too.
{
    echo '#!/bin/bash'
    awk '/^# submission/ {p = 1} /^# ==> / {p = 0} p' "$T/printed.txt"
} >"$T/submit.sh"
shellcheck "$T/submit.sh" || fail "the printed sbatch calls are not shellcheck-clean"
grep -qF -- "--dependency=afterok:\"\$shot_a_1\"" "$T/submit.sh" ||
    fail "the merge does not wait for the clone array"
grep -qF -- "--dependency=afterok:\"\$shot_a_3\"" "$T/submit.sh" || fail "the join does not wait for the chunks"
grep -q "shot_c" "$T/out/shot_c/farm/5-join.sh" || fail "shot_c's join names another shot"
if grep -q "composite" "$T/out/shot_c/farm/4-chunks.sh"; then
    fail "a shot without a scene composites"
fi
echo "PASS: 3 shots, $n scripts and the sbatch calls shellcheck-clean"
