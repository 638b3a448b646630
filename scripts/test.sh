#!/usr/bin/env bash
# Every test: install what is missing, build the release preset (tests, hapticctl, hapticbench),
# run the whole GoogleTest/CTest suite.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release
cmake --build --preset release
ctest --preset release --timeout 1200 --parallel 2
