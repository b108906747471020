#!/usr/bin/env bash
# `pip install --user .` from the source tree (Debian's pip, no network) installs a working package:
# into a temporary user base, with the extension from BUILD_DIR; then `import volscissors` from
# another folder finds the installed copy and runs a live-wire on a tiny image.
# Usage: pip_install_test.sh PYTHON BUILD_DIR SOURCE_DIR (ctest: python_pip_install).
set -euo pipefail
python=$1
build=$(cd "$2" && pwd)
src=$(cd "$3" && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/vs-pip-XXXXXX")
trap 'rm -rf "$tmp"' EXIT
export PYTHONUSERBASE="$tmp/userbase" VOLSCISSORS_BUILD_DIR="$build" PYTHONPATH= PIP_NO_CACHE_DIR=1
"$python" -m pip install --user --no-build-isolation --break-system-packages --no-index --quiet "$src" \
  > "$tmp/pip.log" 2>&1 || { cat "$tmp/pip.log"; exit 1; }
cd "$tmp"
"$python" - "$tmp" <<'PY'
import sys
import numpy as np
import volscissors as vs
assert vs.__file__.startswith(sys.argv[1]), f"imported {vs.__file__}, not the installed copy"
img = np.full((1, 32, 32), 10, dtype=np.float32)
img[0, 8:24, 8:24] = 200
c = vs.livewire(vs.Volume(img), points=[(8, 8), (23, 8), (23, 23), (8, 23)], closed=True, slice="z=0")
assert c.closed and len(c.pixels) >= 56, c
print(f"ok: pip-installed volscissors from {vs.__file__}: closed contour of {len(c.pixels)} pixels")
PY
