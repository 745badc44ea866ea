#!/usr/bin/env bash
# libFuzzer campaign over every reader of augocc (issue 17).
#
#   scripts/fuzz.sh            build the hardening tree (build-fuzz, clang) and run its quick pass:
#                              each fuzzer for a few seconds and the readers' tests under ASan +
#                              UBSan (ctest -L 'fuzz|sanitize'); the README's test command does this
#   scripts/fuzz.sh SECONDS [NAME...]
#                              run each fuzzer (or the NAMEd ones) for SECONDS at nice 19 and print
#                              executions, executions per second and coverage
#   scripts/fuzz.sh --runs N [NAME...]
#                              run each fuzzer for N executions (issue 17's campaign: 1000000),
#                              capped at 30 minutes each
#
# Needs the main build (scripts/build.sh) for libopencv_augocc.so. Findings are written to
# build-fuzz/findings/<name>/ (crash-*, timeout-*, oom-*); the corpus grows in build-fuzz/corpus/.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
[ -f build/lib/libopencv_augocc.so ] || { echo "fuzz: build the library first (scripts/build.sh)" >&2; exit 1; }
LAUNCHER=()
if command -v ccache >/dev/null; then
    LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
cmake -S fuzz -B build-fuzz -DCMAKE_CXX_COMPILER=clang++ -DAUGOCC_BUILD_DIR="$ROOT/build" \
      "${LAUNCHER[@]}" >/dev/null
cmake --build build-fuzz -j2
export LSAN_OPTIONS="suppressions=$ROOT/test/sanitizers/lsan.supp:print_suppressions=0"  # as scripts/sanitize.sh
if [ $# -eq 0 ]; then
    ctest --test-dir build-fuzz --output-on-failure -j2 -L 'fuzz|sanitize'
    exit
fi
LIMIT=()
if [ "$1" = "--runs" ]; then
    [ $# -ge 2 ] || { echo "fuzz: --runs needs a count" >&2; exit 2; }
    LIMIT=(-runs="$2" -max_total_time=1800)
    shift 2
else
    LIMIT=(-max_total_time="$1")
    shift
fi
NAMES=("$@")
[ ${#NAMES[@]} -gt 0 ] || NAMES=(tracks reconstruction calibration clones scene mesh masks)
printf '%-15s %12s %10s %8s %8s %s\n' fuzzer executions execs/s cov ft findings
status=0
for n in "${NAMES[@]}"; do
    mkdir -p "build-fuzz/corpus/$n" "build-fuzz/findings/$n"
    log="build-fuzz/findings/$n/run.log"
    set +e
    nice -n 19 "build-fuzz/bin/fuzz_$n" "${LIMIT[@]}" -timeout=10 \
        -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="build-fuzz/findings/$n/" \
        "build-fuzz/corpus/$n" "fuzz/corpus/$n" >"$log" 2>&1
    rc=$?
    set -e
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1)
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -n 1 | cut -d' ' -f2)
    ft=$(grep -o 'ft: [0-9]*' "$log" | tail -n 1 | cut -d' ' -f2)
    found=$(find "build-fuzz/findings/$n" -name 'crash-*' -o -name 'timeout-*' -o -name 'oom-*' -o -name 'leak-*' | wc -l)
    printf '%-15s %12s %10s %8s %8s %s\n' "$n" "${execs:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" \
        "$found (exit $rc, log $log)"
    [ "$rc" -eq 0 ] || status=1
done
exit $status
