#!/usr/bin/env bash
# README command (a): install what is missing, build, and run `augocc demo` on the embedded
# default (a synthesized scene). Output goes to ./demo_out unless a folder is given.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
build/bin/augocc demo --out-dir "${1:-demo_out}"
