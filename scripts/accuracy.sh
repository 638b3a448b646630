#!/usr/bin/env bash
# The accuracy study, one command: install what is missing (gnuplot among it), build (release), run
# hapticstudy, which writes docs/accuracy/results.csv, docs/accuracy/tables.md, the PNG plots
# (gnuplot) and the tables section of docs/accuracy.md. Under 10 minutes on the 2-core CI machine
# (docs/accuracy.md says how long the last run took); --quick (3 s of each scene's stream, fewer
# pair configurations) under 1 minute, the size CTest study.quick runs.
# Usage: scripts/accuracy.sh [--quick]
#   --quick writes to build/release/study_quick: docs/ keeps the full run's figures.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target hapticstudy
args=(--out docs/accuracy --doc docs/accuracy.md)
for a in "$@"; do
  if [[ $a == --quick ]]; then args=(--out build/release/study_quick --doc ""); fi
done
start=$(date +%s)
build/release/bin/hapticstudy "${args[@]}" "$@"
echo "accuracy.sh: the study took $(($(date +%s) - start)) s"
