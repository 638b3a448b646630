#!/bin/sh
# Resident memory of hapticd on each demo scene (issue 18 point 6; figures in bench/README.md
# "Memory"): the daemon runs the scene on the sim device at 1 kHz on the real clock for a few
# seconds, as `hapticd --demo NAME` does (realtime "prefer": with the memory locked when the
# process may lock it), no network, no web; then VmRSS (resident now, while running) and VmHWM
# (the peak, the scene's load included) from /proc/PID/status, in MiB.
#   scripts/memory.sh [BUILD_DIR] [SECONDS]
set -eu
build=${1:-build/release}
seconds=${2:-3}
hapticd="$build/bin/hapticd"
[ -x "$hapticd" ] || { echo "memory: no $hapticd (build it first)" >&2; exit 2; }
printf '%-12s %10s %10s %s\n' scene rss_mib peak_mib locked
for scene in peg_in_hole gears dynamic stress decomposed; do
  log=$(mktemp)
  "$hapticd" --demo "$scene" --udp "" --shm "" --web "" --log-level info >"$log" 2>&1 &
  pid=$!
  sleep "$seconds"
  status=/proc/$pid/status
  if [ ! -r "$status" ]; then
    echo "memory: hapticd --demo $scene ended early:" >&2
    cat "$log" >&2
    rm -f "$log"
    exit 1
  fi
  rss=$(awk '/^VmRSS:/ {printf "%.1f", $2 / 1024}' "$status")
  hwm=$(awk '/^VmHWM:/ {printf "%.1f", $2 / 1024}' "$status")
  locked=$(awk '/^VmLck:/ {print ($2 > 0) ? "yes" : "no"}' "$status")
  kill -TERM "$pid"
  wait "$pid" || true
  rm -f "$log"
  printf '%-12s %10s %10s %s\n' "$scene" "$rss" "$hwm" "$locked"
done
