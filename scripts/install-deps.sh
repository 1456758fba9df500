#!/usr/bin/env bash
# Installs every Debian package pathlab needs to build and test.
# Usage: scripts/install-deps.sh
# Chromium is installed for the tests that open `pathlab report`'s HTML and `pathlab view`'s page
# in a headless browser (the view's through ChromeDriver and Selenium; both are skipped where
# /usr/bin/chromium is absent). pybind11, NumPy, pytest and
# matplotlib are for the Python module (python/), its tests and the example in examples/.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libembree-dev libtbb-dev libopenexr-dev libstb-dev
  libcli11-dev libfmt-dev nlohmann-json3-dev libpugixml-dev libtinyobjloader-dev libnanoflann-dev
  libopenvdb-dev libassimp-dev libtinygltf-dev zlib1g-dev
  libgtest-dev libbenchmark-dev
  libopenmpi-dev openmpi-bin libxxhash-dev libcpp-httplib-dev
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib
  chromium chromium-driver python3-selenium python3-pil
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "install-deps: all packages present"
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
