#!/usr/bin/env bash
# The readers under AddressSanitizer + UndefinedBehaviorSanitizer, sized for CI (issue 22):
# builds only what the readers need (vs_util, vs_volume, vs_mesh, vs_meshops, vs_io), test_io
# and fuzz_replay in build-asan/ (the folder `make test-asan` uses, so either reuses the other's
# objects), runs every test_io test, then replays the fuzz targets' corpus: the seed corpus of
# scripts/fuzz.sh (made with the Release CLI), DICOM series written with pydicom at known
# geometry, the test files nibabel and pydicom ship (when installed), fuzz/regress/<target>/
# and, when `make fuzz` ran here, its build-fuzz/fuzz-corpus. Any sanitizer report fails.
#   scripts/asan-readers.sh            (make test-readers-asan; .ci/run runs it)
# The whole suite under sanitizers is `make test-asan`; random fuzzing is `make fuzz`.
set -euo pipefail
cd "$(dirname "$0")/.."
B=${ASAN_BUILD:-build-asan}
JOBS=${JOBS:-$(nproc)}
CLI=${VS_CLI:-build/volscissors}
CCACHE=$(command -v ccache >/dev/null && echo "-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache" || true)
start=$(date +%s)

if [ ! -f "$B/CMakeCache.txt" ]; then
  cmake -S . -B "$B" -DCMAKE_BUILD_TYPE=RelWithDebInfo $CCACHE -DVS_SANITIZE=ON -DVS_BUILD_BENCH=OFF \
    > "$B.configure.log" 2>&1 || { cat "$B.configure.log"; exit 1; }
fi
cmake --build "$B" -j "$JOBS" --target test_io fuzz_replay -- --no-print-directory > "$B.readers.log" 2>&1 ||
  { tail -50 "$B.readers.log"; exit 1; }
built=$(date +%s)

export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1
export LSAN_OPTIONS=suppressions=$PWD/scripts/lsan.supp:print_suppressions=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
(cd "$B" && ./test_io --gtest_brief=1)
tested=$(date +%s)

# ---------------------------------------------------------------- corpus
[ -x "$CLI" ] || { echo "asan-readers: $CLI not built (make build first): it makes the seed corpus" >&2; exit 1; }
FUZZ_SEEDS_ONLY=1 FUZZ_BUILD="$B" VS_CLI="$CLI" scripts/fuzz.sh
seeds="$B/fuzz-seeds"
if /usr/bin/python3 -c 'import pydicom, numpy' 2>/dev/null; then
  /usr/bin/python3 tests/io/dicom_fixtures.py "$seeds/gen-dicom" > /dev/null
  mkdir -p "$seeds/dicom"
  find "$seeds/gen-dicom" -type f ! -name '*.json' | while read -r f; do
    cp "$f" "$seeds/dicom/$(echo "$f" | md5sum | cut -c1-12).dcm"
  done
  pyd=$(/usr/bin/python3 -c 'import pydicom, os; print(os.path.join(os.path.dirname(pydicom.__file__), "data", "test_files"))')
  find "$pyd" -maxdepth 1 -name '*.dcm' -size -2M -exec cp {} "$seeds/dicom/" \;
fi
if /usr/bin/python3 -c 'import nibabel' 2>/dev/null; then
  nibd=$(/usr/bin/python3 -c 'import nibabel, os; print(os.path.join(os.path.dirname(nibabel.__file__), "tests", "data"))')
  mkdir -p "$seeds/nifti" "$seeds/niftigz"
  find "$nibd" -maxdepth 1 -name '*.nii' -size -2M -exec cp {} "$seeds/nifti/" \;
  find "$nibd" -maxdepth 1 -name '*.nii.gz' -size -2M -exec cp {} "$seeds/niftigz/" \;
fi

inputs=0
while IFS='|' read -r name ext reader; do
  files=()
  for dir in "$seeds/$name" "fuzz/regress/$name" "build-fuzz/fuzz-corpus/$name"; do
    [ -d "$dir" ] && while IFS= read -r -d '' f; do files+=("$f"); done < <(find "$dir" -type f -print0)
  done
  [ ${#files[@]} -eq 0 ] && continue
  "$B/fuzz_replay" "$reader" "$ext" "${files[@]}" > /dev/null
  inputs=$((inputs + ${#files[@]}))
done < <(sed -n 's/^ *"\([a-z]*|[.a-z]*|[a-z]*\)"\(.*\)$/\1/p' fuzz/CMakeLists.txt)
end=$(date +%s)
echo "asan-readers: build $((built - start)) s, test_io $((tested - built)) s, corpus replay $((end - tested)) s" \
  "($inputs inputs), no sanitizer report"
