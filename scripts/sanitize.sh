#!/usr/bin/env bash
# The whole suite under AddressSanitizer + UndefinedBehaviorSanitizer (issue 17): configures
# build-asan with -DAUGOCC_SANITIZE=ON (no perf suite), builds it and runs ctest there; extra
# arguments go to ctest (e.g. -R Augocc_Io, -L sanitize, -E accuracy). Slow: the sanitized suite
# takes several times the plain one; run it niced in the background. The README's test command
# runs the quick sanitizer pass instead (scripts/fuzz.sh, ctest -L sanitize in build-fuzz).
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
bash scripts/setup.sh
LAUNCHER=()
if command -v ccache >/dev/null; then
    LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
fi
# Leaks of system libraries are suppressed by name (test/sanitizers/lsan.supp, with reasons);
# UBSan stops at the first report so a test fails on it.
# print_suppressions=0: the used-suppressions table goes to stderr at every exit, and tests that
# check a command's one error line or every line of a log would read it as output.
export LSAN_OPTIONS="suppressions=$ROOT/test/sanitizers/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0"
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAUGOCC_SANITIZE=ON \
      -DAUGOCC_BUILD_PERF=OFF "${LAUNCHER[@]}"
cmake --build build-asan -j2
cd build-asan
ctest --output-on-failure -j2 --timeout 3600 "$@"
