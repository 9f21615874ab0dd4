#!/usr/bin/env bash
# Installs every Debian 12 package Scalespace needs to build, test and run its benchmarks.
# Idempotent: when everything is present it only checks (well under a second).
# Runs as root (fresh machine) or as a user with sudo.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libnanoflann-dev libtbb-dev
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev
  libcli11-dev nlohmann-json3-dev libfmt-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libpng-dev zlib1g-dev
  clang-format
  python3 python3-numpy
  pybind11-dev python3-pybind11 python3-pytest
  libcpp-httplib-dev  # `scalespace view`: the local HTTP server
)
# Optional: without them the project still builds and tests (the viewer page is not bundled, its
# end-to-end test skips), so a failure to install them is a warning. Chromium: the viewer's
# end-to-end test drives it headless (never a downloaded browser). Node.js and npm bundle the page
# (scripts/setup_web.sh): Debian's, unless a Node.js with npm is installed already (NodeSource's
# nodejs package brings its own npm).
optional=(chromium)
command -v npm >/dev/null || optional+=(nodejs npm)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

missing_optional=()
for p in "${optional[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing_optional+=("$p")
done

web() { "$(dirname "$0")/setup_web.sh"; }

if ((${#missing[@]} == 0 && ${#missing_optional[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  web
  exit 0
fi

echo "setup: installing ${missing[*]}"
sudo=()
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "setup: run as root or install sudo" >&2; exit 1; }
  sudo=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
# Refresh the package lists only when a package cannot be found in them.
if ((${#missing[@]} > 0)) &&
  ! "${sudo[@]}" apt-get install -y --no-install-recommends "${missing[@]}"; then
  "${sudo[@]}" apt-get update
  "${sudo[@]}" apt-get install -y --no-install-recommends "${missing[@]}"
fi
if ((${#missing_optional[@]} > 0)) &&
  ! "${sudo[@]}" apt-get install -y --no-install-recommends "${missing_optional[@]}" &&
  ! { "${sudo[@]}" apt-get update &&
    "${sudo[@]}" apt-get install -y --no-install-recommends "${missing_optional[@]}"; }; then
  echo "setup: warning: could not install ${missing_optional[*]}: the viewer page or its" \
    "end-to-end test will be skipped" >&2
fi
web
