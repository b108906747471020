#!/usr/bin/env bash
# Installs the Debian 12 packages volscissors needs to build, test and run the demo.
# Idempotent and quiet when everything is already there. Needs root (or sudo).
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config
  libinsighttoolkit5-dev libgdcm-dev     # image I/O (NIfTI, NRRD, MetaImage, DICOM, PNG, TIFF)
  libeigen3-dev libcli11-dev nlohmann-json3-dev libpng-dev zlib1g-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  python3                                # demo summaries and the demo's phantom fallback read JSON
  libvtk9-dev                            # mesh algorithms (iso-surface, smoothing, decimation), behind src/meshops only
  libglfw3-dev libimgui-dev libgl-dev libegl-dev libgl1-mesa-dri libegl-mesa0 xvfb xauth xdotool   # the viewer; offscreen tests, real input events
  pybind11-dev python3-dev python3-numpy python3-pytest python3-dask python3-distributed  # Python bindings, cohorts
  clang libfuzzer-14-dev libclang-rt-14-dev   # fuzz targets (libFuzzer) run briefly in CI
  libboost-dev                           # the cutting surface's minimum cut (Boost.Graph Boykov-Kolmogorov, header-only)
  libblosc-dev python3-zarr              # OME-Zarr volumes (blosc chunks); python3-zarr cross-checks the reader in tests
  python3-skimage                        # the peer of bench/full_map_variance.sh and bench/engine_vs_peers.sh
  python3-scipy                          # the airway wall distance (EDT) of bench/trace_measures.py, tested in tests/python
  python3-pip                            # the `pip install --user .` test (tests/install/pip_install_test.sh)
  python3-nibabel python3-pydicom        # reader tests: peer corpora (their test data) and DICOM series written at test time
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "install-deps: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to apt-get install ${missing[*]}" >&2; exit 1; }
  SUDO="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
