#!/usr/bin/env bash
# `make install`'s tree serves a user's project: installs BUILD into a temporary prefix, then builds
# examples/core_example against it with CMake (find_package(volscissors), volscissors::core) and
# with pkg-config, runs both, and checks that the installed core holds no io (ITK) header.
# Usage: install_example_test.sh BUILD_DIR SOURCE_DIR (ctest: install_example).
set -euo pipefail
build=$(cd "$1" && pwd)
src=$(cd "$2" && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/vs-install-XXXXXX")
trap 'rm -rf "$tmp"' EXIT
prefix="$tmp/prefix"

cmake --install "$build" --prefix "$prefix" > "$tmp/install.log" || { cat "$tmp/install.log"; exit 1; }
for f in include/volscissors/scissors/live_wire.h include/volscissors/phantom/phantom.h; do
  [[ -f "$prefix/$f" ]] || { echo "FAIL: $f not installed"; exit 1; }
done
if [[ -e "$prefix/include/volscissors/io" ]]; then echo "FAIL: io headers installed with the core"; exit 1; fi
cfg=$(find "$prefix" -name volscissorsConfig.cmake | head -1)
pc=$(find "$prefix" -name volscissors.pc | head -1)
[[ -n "$cfg" && -n "$pc" ]] || { echo "FAIL: no volscissorsConfig.cmake or volscissors.pc under $prefix"; exit 1; }

# CMake: find_package(volscissors) + target_link_libraries(x volscissors::core).
cmake -S "$src/examples/core_example" -B "$tmp/cmake-build" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_BUILD_TYPE=Release > "$tmp/configure.log" 2>&1 || { cat "$tmp/configure.log"; exit 1; }
cmake --build "$tmp/cmake-build" > "$tmp/build.log" 2>&1 || { cat "$tmp/build.log"; exit 1; }
out=$("$tmp/cmake-build/core_example")
echo "cmake:      $out"

# pkg-config: one compiler line.
libdir=$(dirname "$(dirname "$pc")")
flags=$(PKG_CONFIG_PATH="$(dirname "$pc")" pkg-config --cflags --libs volscissors)
${CXX:-c++} "$src/examples/core_example/main.cpp" $flags -o "$tmp/pc_example"
out2=$(LD_LIBRARY_PATH="$libdir" "$tmp/pc_example")
echo "pkg-config: $out2"
[[ "$out" == "$out2" ]] || { echo "FAIL: the two builds disagree"; exit 1; }
echo "ok: the installed core builds and runs a user's project (CMake and pkg-config)"
