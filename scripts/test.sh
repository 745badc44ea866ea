#!/usr/bin/env bash
# README command (b): install what is missing, build, and run every test; then the hardening
# tree's quick pass (scripts/fuzz.sh: each reader's fuzzer for a few seconds and the readers'
# tests under ASan + UBSan, ctest -L 'fuzz|sanitize' in build-fuzz).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
(cd build && ctest --output-on-failure -j2 --timeout 900 -LE kill)
bash scripts/fuzz.sh
