#!/usr/bin/env bash
# The main job: install what is missing, build the release preset, run hapticd on its embedded
# defaults (docs/architecture.md, "hapticd defaults"): the sim device driven by its built-in gentle
# motion (or by clients' pose commands), the built-in peg-in-hole demo scene, 1 kHz, SCHED_FIFO
# when permitted (else a warning and normal priority). It serves until SIGTERM or Ctrl-C, which
# ramp the force to zero and exit 0. Arguments are passed to hapticd (see hapticd --help).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release
cmake --build --preset release
exec build/release/bin/hapticd "$@"
