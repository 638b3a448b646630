#!/usr/bin/env bash
# The accuracy study, one command: install what is missing, build (release), run hapticstudy, which
# writes docs/accuracy/results.csv, docs/accuracy/tables.md, the PNG plots (gnuplot) and the
# tables section of docs/accuracy.md. Takes about 2 minutes on the 2-core CI machine.
# Usage: scripts/accuracy.sh [--quick]    (--quick: a smoke run with fewer configurations)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release
cmake --build --preset release --target hapticstudy
exec build/release/bin/hapticstudy --out docs/accuracy --doc docs/accuracy.md "$@"
