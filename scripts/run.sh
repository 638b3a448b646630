#!/usr/bin/env bash
# The main job: install what is missing, build the release preset, run the main program.
# Until the daemon exists (issue 7), the main program is hapticctl answering the example pair
# queries of docs/examples/pairs.jsonl (the offline narrow phase, DESIGN.md "Pair queries").
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release
cmake --build --preset release
exec build/release/bin/hapticctl query docs/examples/pairs.jsonl
