#!/usr/bin/env bash
# Same-run before/after timing of one benchmark binary at two commits (issue 10: the renderer and
# engine splits). Both binaries are compiled here with the same compiler and flags (-O3 -DNDEBUG,
# as the Release build) straight from each commit's sources, without ITK (these benchmarks need
# only the core modules), then run alternately ROUNDS times, single-threaded; prints one line per
# run and the per-round ratios after/before of the mean time per iteration.
#   bench/before_after.sh BENCH OLD_COMMIT NEW_COMMIT "MODULES" FILTER [ROUNDS]
#   e.g. bench/before_after.sh bench_render 970dab2 HEAD "util volume mesh phantom render" 'BM_Full_Shaded$' 5
set -euo pipefail
bench=$1 old=$2 new=$3 modules=$4 filter=$5 rounds=${6:-5}
repo=$(cd "$(dirname "$0")/.." && pwd)
work=${BEFORE_AFTER_DIR:-/tmp/vs_before_after}
mkdir -p "$work"
build() {  # build COMMIT -> binary path
  local commit=$1 sha dir
  sha=$(git -C "$repo" rev-parse --short "$commit")
  dir="$work/src_$sha"
  [ -d "$dir" ] || git -C "$repo" worktree add --detach "$dir" "$sha" > /dev/null 2>&1
  local bin="$work/${bench}_$sha"
  if [ ! -x "$bin" ]; then
    local srcs=""
    for m in $modules; do srcs="$srcs $(ls "$dir"/src/"$m"/*.cpp)"; done
    mkdir -p "$work/obj_$sha"
    local objs=""
    for s in "$dir/bench/$bench.cpp" $srcs; do
      local o="$work/obj_$sha/$(echo "${s#$dir/}" | tr / _).o"
      ${CXX:-g++} -O3 -DNDEBUG -std=c++20 -I"$dir/src" -isystem /usr/include/eigen3 -c "$s" -o "$o"
      objs="$objs $o"
    done
    ${CXX:-g++} -O3 $objs -o "$bin" -lbenchmark -lpthread
  fi
  echo "$bin"
}
before=$(build "$old") after=$(build "$new")
echo "# $bench: before $old ($before), after $new ($after); filter $filter; $rounds rounds; $(uptime)"
for r in $(seq "$rounds"); do
  tb=$(VS_THREADS=1 "$before" --benchmark_filter="$filter" --benchmark_format=csv 2>/dev/null | grep -v '^name' | cut -d, -f1,4)
  ta=$(VS_THREADS=1 "$after" --benchmark_filter="$filter" --benchmark_format=csv 2>/dev/null | grep -v '^name' | cut -d, -f1,4)
  paste -d, <(echo "$tb") <(echo "$ta") | awk -F, -v r="$r" '{printf "round %d %s before %.2f after %.2f ratio %.3f\n", r, $1, $2, $4, $4/$2}'
done
