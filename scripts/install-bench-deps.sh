#!/usr/bin/env bash
# Extra Debian packages for the side-by-side benchmarks in bench/ (the peers in
# ../shared/peers: scikit-image, SciPy, OpenCV, VTK). Not needed to build or test.
set -euo pipefail
PACKAGES=(python3-numpy python3-scipy python3-skimage python3-opencv python3-vtk9 python3-nibabel time xvfb xauth)
missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
