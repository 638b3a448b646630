#!/usr/bin/env bash
# clang-tidy with the repository's .clang-tidy over C++ sources, using the release preset's
# compile_commands.json (configure it first: cmake --preset release).
# Usage: scripts/tidy.sh                 the .cpp files changed since HAPTICD_TIDY_BASE (default: the
#                                        last 20 commits), or every file if that cannot be told
#        scripts/tidy.sh --all           every .cpp file of the build
#        scripts/tidy.sh FILE...         those files
# Exit 1 when clang-tidy reports an error or a warning in the project's own files.
set -euo pipefail
cd "$(dirname "$0")/.."
db=build/release
[[ -f $db/compile_commands.json ]] || { echo "tidy: $db/compile_commands.json missing (cmake --preset release)" >&2; exit 2; }
command -v clang-tidy >/dev/null || { echo "tidy: clang-tidy not found (apt-get install clang-tidy)" >&2; exit 2; }
files=()
if [[ "${1:-}" == "--all" ]]; then
  mapfile -t files < <(git ls-files 'core/*.cpp' 'daemon/*.cpp' 'protocol/*.cpp' 'client/*.cpp' 'scenes/*.cpp')
elif [[ $# -gt 0 ]]; then
  files=("$@")
else
  base=${HAPTICD_TIDY_BASE:-HEAD~20}
  if git rev-parse -q --verify "$base^{commit}" >/dev/null; then
    mapfile -t files < <(git diff --name-only --diff-filter=AM "$base" -- 'core/*.cpp' 'daemon/*.cpp' 'protocol/*.cpp' 'client/*.cpp' 'scenes/*.cpp')
  else
    mapfile -t files < <(git ls-files 'core/*.cpp' 'daemon/*.cpp' 'protocol/*.cpp' 'client/*.cpp' 'scenes/*.cpp')
  fi
fi
if [[ ${#files[@]} -eq 0 ]]; then echo "tidy: no files to check"; exit 0; fi
echo "tidy: ${#files[@]} files"
out=$(mktemp); trap 'rm -f "$out"' EXIT
# -header-filter: report in our own headers too, never in the system's
printf '%s\n' "${files[@]}" | xargs -P 2 -n 4 clang-tidy -p "$db" --quiet \
    -header-filter="^$(pwd)/(core|daemon|protocol|client|scenes)/" >"$out" 2>/dev/null || true
n=$(grep -cE '^/.*: (warning|error):' "$out" || true)
if [[ $n -gt 0 ]]; then
  grep -E '^/.*: (warning|error):' "$out" | sort -u >&2
  echo "tidy: $n findings" >&2
  exit 1
fi
echo "tidy: clean"
