#!/bin/sh
# Checks systemd/hapticd.service with ExecStart pointed at a built hapticd:
#   check_unit.sh verify   UNIT BINARY CONFIG  -- `systemd-analyze verify`; fails on ANY output
#   check_unit.sh security UNIT BINARY CONFIG  -- `systemd-analyze security --offline=true`;
#                                                 fails when the exposure score is above 3.0
set -eu
mode=$1 unit=$2 binary=$3 config=$4
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed "s|^ExecStart=.*|ExecStart=$binary --config $config|" "$unit" > "$work/hapticd.service"
grep -q "^ExecStart=$binary " "$work/hapticd.service" || { echo "no ExecStart line in $unit"; exit 1; }
cd "$work"
case "$mode" in
  verify)
    # verify prints its warnings (unknown keys, bad values, missing binaries) and often still
    # exits 0: any output at all is a failure
    set +e
    out=$(systemd-analyze verify "$work/hapticd.service" 2>&1)
    rc=$?
    set -e
    if [ -n "$out" ] || [ $rc -ne 0 ]; then
      echo "systemd-analyze verify (exit $rc) said:"
      echo "$out"
      exit 1
    fi
    echo "systemd-analyze verify: no warnings"
    ;;
  security)
    out=$(systemd-analyze security --offline=true --no-pager "$work/hapticd.service" 2>&1) || true
    line=$(printf '%s\n' "$out" | grep 'Overall exposure level' || true)
    [ -n "$line" ] || { echo "no exposure level in:"; echo "$out"; exit 1; }
    score=$(printf '%s\n' "$line" | sed -n 's/.*: \([0-9][0-9]*\.[0-9]\).*/\1/p')
    echo "$line"
    [ -n "$score" ] || { echo "cannot read the score"; exit 1; }
    # fail above 3.0 (the score has one decimal)
    if awk -v s="$score" 'BEGIN { exit !(s > 3.0) }'; then
      printf '%s\n' "$out" | grep '✗' || true
      echo "exposure $score is above 3.0"
      exit 1
    fi
    ;;
  *) echo "usage: $0 verify|security UNIT BINARY CONFIG"; exit 2 ;;
esac
