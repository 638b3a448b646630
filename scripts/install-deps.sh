#!/usr/bin/env bash
# Installs the Debian 12 packages hapticd needs to build, test and benchmark, when missing.
# Idempotent: a machine that has them all does nothing (no apt-get update, no network).
# Usage: scripts/install-deps.sh            (all packages)
#        scripts/install-deps.sh --print    (just list the package names)
set -euo pipefail

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  clang libclang-rt-14-dev            # the asan preset's UBSan runtime and the fuzz targets
  clang-format clang-tidy             # scripts/format.sh and scripts/tidy.sh (CI enforces the format)
  libglm-dev                          # math (core)
  libqhull-dev                        # convex hulls (core)
  nlohmann-json3-dev                  # hapticctl query: JSON lines
  libcli11-dev                        # command-line parsing
  libgtest-dev libgmock-dev           # tests
  libbenchmark-dev                    # hapticbench
  libccd-dev libfcl-dev libbullet-dev # peers compared in hapticbench
  libtinygltf-dev                     # tests: an independent glTF reader
  libdraco-dev libmeshoptimizer-dev   # scenes: Draco and meshopt compressed geometry (core/scene)
  libassimp-dev                       # hapticctl import: .obj .stl .ply .off
  libbullet-extras-dev                # hapticbench: the HACD decomposition peer
  libtomlplusplus-dev                 # config/hapticd.toml
  libsystemd-dev systemd              # sd_notify (READY, WATCHDOG); systemd-analyze verify in CI
  libhidapi-dev                       # hid device backend
  libusb-1.0-0-dev                    # usb device backend (hotplug, bulk)
  libsodium-dev                       # protocol: per-packet MAC, SHA-256 of scene uploads
  gnuplot-nox                         # plots of the accuracy study
  help2man                            # hapticd(8), hapticctl(1) from their --help
  lintian                             # scripts/package.sh --check: the Debian package's lint
  libboost-dev                        # the web API: Boost.Beast (HTTP, WebSocket), header-only
  chromium                            # the viewer's browser test (web.viewer, Playwright drives it)
)

# the viewer's npm packages (web/package.json: three.js; playwright-core for its test), when npm
# is there; without them the viewer's page has no 3-D view and web.viewer is skipped
npm_install() {
  local web_dir
  web_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/web"
  if [[ ! -d "$web_dir/node_modules/three" ]]; then
    if command -v npm >/dev/null; then
      echo "install-deps: npm install in $web_dir"
      (cd "$web_dir" && npm install --no-audit --no-fund)
    else
      echo "install-deps: npm not found: the viewer's three.js is not installed (web/package.json)"
    fi
  fi
}

if [[ "${1:-}" == "--print" ]]; then
  printf '%s\n' "${PACKAGES[@]}"
  exit 0
fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  npm_install
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
npm_install
echo "install-deps: done"
