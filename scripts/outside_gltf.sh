#!/usr/bin/env bash
# Checks glTF files written by others (Blender, Godot, the Khronos and OMI samples, Draco and
# meshopt test data) with the built hapticctl and hapticd, and prints one table row per file.
# It fetches nothing: the files are not ours and stay out of the repository (docs/outside-files.md
# names the sources and commits). Without the folder it says so and exits 0.
# Usage: scripts/outside_gltf.sh [DIR] [BUILD_DIR]
#   DIR        folder searched (recursively) for *.gltf and *.glb (default: $OUTSIDE_GLTF_DIR,
#              else /work/outside)
#   BUILD_DIR  the build with bin/hapticctl and bin/hapticd (default: build/release)
# Columns: file (relative to DIR); check: "ok" or "refused: <first problem>" (hapticctl check);
# bodies: static/kinematic/dynamic; joints: all of them (simulated or not); groups: the distinct
# collision behaviours of the colliders (1 without filters); triggers: trigger primitives;
# daemon: the exit status of `hapticd --scene FILE --check-config` (0 loads, 1 refused).
# Exit 0 when every file was checked (whatever the results), 2 on a missing tool.
set -euo pipefail
cd "$(dirname "$0")/.."
dir="${1:-${OUTSIDE_GLTF_DIR:-/work/outside}}"
build="${2:-build/release}"
if [[ ! -d "$dir" ]]; then
  echo "outside_gltf: no folder $dir: nothing to check (the outside files are fetched by hand;" \
       "docs/outside-files.md)"
  exit 0
fi
hapticctl="$build/bin/hapticctl"
hapticd="$build/bin/hapticd"
for tool in "$hapticctl" "$hapticd"; do
  [[ -x "$tool" ]] || { echo "outside_gltf: $tool not built" >&2; exit 2; }
done
command -v python3 >/dev/null || { echo "outside_gltf: python3 not found" >&2; exit 2; }

summarise() {  # stdin: hapticctl check --json; prints "check|bodies|joints|groups|triggers"
  python3 -c '
import json, sys
r = json.load(sys.stdin)
if not r.get("ok"):
    p = r["problems"][0]
    more = len(r["problems"]) - 1
    what = (p["where"] + ": " + p["what"]).replace("|", "/")
    if len(what) > 160:
        what = what[:157] + "..."
    print("refused: " + what + (" (+%d more)" % more if more else "") + "|-|-|-|-")
    sys.exit(0)
m = {"static": 0, "kinematic": 0, "dynamic": 0}
for b in r["bodies"]:
    m[b["motion"]] += 1
solid = [p for p in r["primitives"] if not p["trigger"]]
groups = len({(p["group"], p["mask"]) for p in solid})
triggers = len(r["primitives"]) - len(solid)
print("ok|%d/%d/%d|%d|%d|%d" % (m["static"], m["kinematic"], m["dynamic"],
      r["joints"] + r["unsimulated_joints"], groups, triggers))
'
}

echo "| file | check | bodies s/k/d | joints | groups | triggers | daemon |"
echo "|---|---|---|---|---|---|---|"
while IFS= read -r -d '' file; do
  rel="${file#"$dir"/}"
  json=$("$hapticctl" check --json "$file" 2>/dev/null || true)
  if [[ -z "$json" ]]; then
    row="no report (hapticctl crashed?)|-|-|-|-"
  else
    row=$(summarise <<<"$json")
  fi
  daemon=0
  "$hapticd" --scene "$file" --check-config --realtime off --clock virtual --device sim \
    >/dev/null 2>&1 || daemon=$?
  echo "| $rel | ${row//|/ | } | $daemon |"
done < <(find "$dir" -type f \( -name '*.gltf' -o -name '*.glb' \) -print0 | sort -z)
